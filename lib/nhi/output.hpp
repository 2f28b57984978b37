// Result files written whole or not at all: claim a temporary file beside the
// target first (so an unwritable path fails before a long run), write, fsync,
// rename.  Destroying an uncommitted AtomicFile removes the temporary.
#pragma once

#include <string>

namespace nhi {

class AtomicFile {
 public:
  // Throws std::runtime_error (naming the path) if the target is a directory or
  // the temporary cannot be created.
  explicit AtomicFile(const std::string& path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  // Write text and rename onto the target; throws std::runtime_error on failure.
  void commit(const std::string& text);
  void discard();

 private:
  std::string path_, tmp_;
  int fd_ = -1;
};

}  // namespace nhi
