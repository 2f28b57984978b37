#include "nhi/runner/output.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace nhi {

namespace {

bool is_short_row(const nlohmann::json& j) {
  if (j.size() > 16) return false;
  for (const auto& e : j)
    if (e.is_structured()) return false;
  return true;
}

void append_lines(std::string& out, const nlohmann::json& j, size_t depth) {
  if (j.is_object() && !j.empty()) {
    out += "{\n";
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!first) out += ",\n";
      first = false;
      out.append(depth + 1, ' ');
      out += nlohmann::json(it.key()).dump();
      out += ": ";
      append_lines(out, it.value(), depth + 1);
    }
    out += '\n';
    out.append(depth, ' ');
    out += '}';
  } else if (j.is_array() && !is_short_row(j)) {
    out += "[\n";
    bool first = true;
    for (const auto& e : j) {
      if (!first) out += ",\n";
      first = false;
      out.append(depth + 1, ' ');
      append_lines(out, e, depth + 1);
    }
    out += '\n';
    out.append(depth, ' ');
    out += ']';
  } else {
    out += j.dump();
  }
}

}  // namespace

std::string json_lines(const nlohmann::json& j) {
  std::string out;
  append_lines(out, j, 0);
  out += '\n';
  return out;
}

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw std::runtime_error("output '" + path + "' is a directory");
  tmp_ = path + ".tmp." + std::to_string(::getpid());
  do {
    fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  } while (fd_ < 0 && errno == EINTR);
  if (fd_ < 0) throw std::runtime_error("cannot write output '" + path + "': " + std::strerror(errno));
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(tmp_.c_str());
    fd_ = -1;
  }
}

void AtomicFile::commit(const std::string& text) {
  if (fd_ < 0) throw std::runtime_error("output '" + path_ + "' already closed");
  // The first failure's errno, and what failed: an errno read later may be
  // another call's (or stale).
  int err = 0;
  const char* what = "";
  size_t done = 0;
  while (err == 0 && done < text.size()) {
    const ssize_t k = ::write(fd_, text.data() + done, text.size() - done);
    if (k < 0 && errno == EINTR) continue;  // a signal (SIGINT/SIGTERM set a flag) before any byte
    if (k < 0)
      err = errno, what = "write";
    else
      done += static_cast<size_t>(k);
  }
  if (err == 0 && ::fsync(fd_) != 0) err = errno, what = "fsync";
  if (::close(fd_) != 0 && err == 0) err = errno, what = "close";
  fd_ = -1;
  if (err == 0 && std::rename(tmp_.c_str(), path_.c_str()) != 0) err = errno, what = "rename";
  if (err != 0) {
    ::unlink(tmp_.c_str());
    throw std::runtime_error("cannot write output '" + path_ + "' (" + what + "): " + std::strerror(err));
  }
}

}  // namespace nhi
