// Result files written whole or not at all: claim a temporary file beside the
// target first (so an unwritable path fails before a long run), write, fsync,
// rename.  Destroying an uncommitted AtomicFile removes the temporary.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace nhi {

// A result's text: the JSON with each object member, and each element of an
// array that is not a short row of numbers, on a line of its own (rows of at
// most 16 scalars stay on one line), so that a rerun that moves a few numbers
// changes a few lines.  The numbers are written as nlohmann::json::dump()
// writes them; the text ends with a newline.  JSON has no NaN or Infinity: a
// non-finite number (a diagnostic that overflowed) is written as null, so that
// the file stays JSON that jq, Python's json and nlohmann read, and a reader
// expecting a number finds none rather than a string; messages, which are for
// people, say NaN, Infinity or -Infinity (scene_detail::show()).
std::string json_lines(const nlohmann::json& j);

class AtomicFile {
 public:
  // Throws std::runtime_error (naming the path) if the target is a directory or
  // the temporary cannot be created.
  explicit AtomicFile(const std::string& path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  // Write text and rename onto the target; throws std::runtime_error on failure,
  // naming the path, the call that failed and why (strerror), the temporary removed.
  void commit(const std::string& text);
  void discard();

 private:
  std::string path_, tmp_;
  int fd_ = -1;
};

}  // namespace nhi
