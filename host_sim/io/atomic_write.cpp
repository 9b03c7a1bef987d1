#include "io/atomic_write.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <random>

#include "io/recording.hpp"

namespace jg::io {
namespace {

// The temporary files that exist now, for the signal handler. Fixed storage: the handler may
// only read memory and call async-signal-safe functions (unlink, signal, raise).
constexpr int kSlots = 32;
constexpr std::size_t kPathBytes = 4096;
char g_tmp_path[kSlots][kPathBytes];
std::atomic<bool> g_tmp_live[kSlots];
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler reads these flags");
std::mutex g_slot_mutex;  ///< taken by threads listing or unlisting, never by the handler
bool g_slot_taken[kSlots];

extern "C" void remove_tmp_and_reraise(int sig) {
  for (int k = 0; k < kSlots; ++k) {
    if (g_tmp_live[k].load()) ::unlink(g_tmp_path[k]);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// Installs the handler for each terminating signal still at its default (a command with
/// its own handler, e.g. `plant` stopping cleanly, keeps it; an ignored signal cannot end
/// the process). Checked at each temporary file: the disposition may have changed.
void install_handler() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;
    struct sigaction sa {};
    sa.sa_handler = remove_tmp_and_reraise;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}

int list_tmp(const std::string& path) {
  if (path.size() >= kPathBytes) return -1;
  const std::lock_guard<std::mutex> lock(g_slot_mutex);
  install_handler();
  for (int k = 0; k < kSlots; ++k) {
    if (g_slot_taken[k]) continue;
    g_slot_taken[k] = true;
    std::memcpy(g_tmp_path[k], path.c_str(), path.size() + 1);
    g_tmp_live[k].store(true);
    return k;
  }
  return -1;  // more temporary files at once than slots: that one is not removed on a signal
}

void unlist_tmp(int slot) {
  if (slot < 0) return;
  g_tmp_live[slot].store(false);
  const std::lock_guard<std::mutex> lock(g_slot_mutex);
  g_slot_taken[slot] = false;
}

/// `<target>.<pid>.<counter>.<random>.tmp`, the target's name cut so that the whole stays
/// within a file name's 255 bytes.
std::filesystem::path tmp_name(const std::filesystem::path& target) {
  static std::atomic<unsigned long> counter{0};
  thread_local std::mt19937_64 rng{std::random_device{}() ^ static_cast<std::uint64_t>(::getpid())};
  char suffix[96];
  std::snprintf(suffix, sizeof suffix, ".%ld.%lu.%08llx.tmp", static_cast<long>(::getpid()), counter.fetch_add(1),
                static_cast<unsigned long long>(rng() & 0xffffffffULL));
  const std::string name = target.filename().string().substr(0, 150);
  return target.parent_path() / (name + suffix);
}
}  // namespace

TempFile::TempFile(const std::filesystem::path& target) : target_(target) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    tmp_ = tmp_name(target);
    // O_EXCL: the name is this writer's alone, even against a process of the same id in
    // another container sharing the folder.
    const int fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      slot_ = list_tmp(tmp_.string());
      return;
    }
    if (errno != EEXIST) break;
  }
  throw FormatError(target.string() + ": cannot write (" + std::strerror(errno) + "; does its folder exist and is it writable?)");
}

TempFile::~TempFile() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(tmp_, ignored);
  }
  unlist_tmp(slot_);
}

void TempFile::commit() {
  std::error_code ec;
  std::filesystem::rename(tmp_, target_, ec);
  if (ec) {
    std::filesystem::remove(tmp_, ec);
    throw FormatError(target_.string() + ": cannot write: " + ec.message());
  }
  committed_ = true;
}

FolderLock::FolderLock(const std::filesystem::path& folder) {
  const std::string dir = folder.empty() ? std::string(".") : folder.string();
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ >= 0 && ::flock(fd_, LOCK_EX) != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::filesystem::path target(path);
  if (std::filesystem::is_directory(target)) throw FormatError(path + ": is a directory, not a file to write");
  TempFile tmp(target);
  {
    std::ofstream out(tmp.path(), std::ios::binary | std::ios::trunc);
    if (!out) throw FormatError(path + ": cannot write (does its folder exist?)");
    out << text;
    out.flush();
    if (!out) throw FormatError(path + ": write failed");
  }
  tmp.commit();
}

void write_json_atomic(const std::string& path, const nlohmann::json& j) {
  write_text_atomic(path, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace jg::io
