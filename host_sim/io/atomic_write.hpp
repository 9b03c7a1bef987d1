// One output writer for every file the tools write: to a temporary file in the same folder,
// every write checked, then renamed into place. A failure (a missing folder, a full disk, a
// directory in the way) throws naming the path and leaves neither a partial file nor the
// temporary one: no command reports success without its file.
//
// The temporary name is unique to the writer (process id, a counter and a random number),
// so two processes writing the same output never write into one file: the output is one
// of the two complete files, never a mix. SIGINT, SIGTERM and SIGHUP while a temporary
// file exists remove it (when the process has not installed its own handler).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace jg::io {

/// Writes `text` to `path` atomically; throws io::FormatError naming the path on failure.
void write_text_atomic(const std::string& path, const std::string& text);

/// JSON (2-space indent, invalid UTF-8 replaced) through write_text_atomic.
void write_json_atomic(const std::string& path, const nlohmann::json& j);

/// A temporary file beside `target`, created empty with a name no other writer uses
/// (`<target>.<pid>.<counter>.<random>.tmp`). Removed by the destructor unless commit()
/// renamed it onto the target, and by a terminating signal while it exists.
class TempFile {
 public:
  explicit TempFile(const std::filesystem::path& target);
  ~TempFile();
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return tmp_; }
  [[nodiscard]] const std::filesystem::path& target() const { return target_; }
  /// Renames the temporary file onto the target; throws io::FormatError naming the target
  /// on failure (the temporary file is then removed).
  void commit();

 private:
  std::filesystem::path target_, tmp_;
  int slot_ = -1;  ///< its entry in the signal handler's list, -1 when not listed
  bool committed_ = false;
};

/// An exclusive advisory lock (flock) on a folder, held while several renames into it must
/// be seen together by another writer taking the same lock (a recording's CSV and its JSON
/// side file). Leaves no file behind; without locking support it does nothing.
class FolderLock {
 public:
  explicit FolderLock(const std::filesystem::path& folder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace jg::io
