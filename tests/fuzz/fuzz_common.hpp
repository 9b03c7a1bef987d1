// Shared by the reader fuzz targets: the readers take a path, so each input is written to a
// file in a per-process folder and read from there (the readers stay as the CLI uses them).
// What a reader may do with bad input: throw its error type with a message that starts with
// the file's path (it names the file). Anything else is a finding: a crash, a sanitizer
// report, a leak, another exception (yaml-cpp's, nlohmann's, std::stoul's...) or an error
// that does not name the file. Findings abort, so libFuzzer saves the input.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

namespace jg::fuzz {

/// The per-process folder (created once, removed at exit).
inline const std::filesystem::path& work_dir() {
  static const std::filesystem::path dir = [] {
    const char* base = std::getenv("JG_FUZZ_TMP");
    std::filesystem::path d = std::filesystem::path(base ? base : "/tmp") / ("jg_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(work_dir(), ec);
    });
    return d;
  }();
  return dir;
}

/// Writes the input as `name` in the work folder; returns its path.
inline std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const std::string path = (work_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz harness: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

[[noreturn]] inline void finding(const char* what, const std::string& message) {
  std::fprintf(stderr, "FINDING: %s: %s\n", what, message.c_str());
  std::abort();
}

/// Runs `read`; `Error` (the reader's documented error type) is fine when its message
/// starts with `path`, anything else is a finding.
/// Whether the message starts with the path of an existing file other than `path` (a file
/// the input refers to, e.g. a scenario's robot model, whose own errors name it).
inline bool names_existing_file(const std::string& message) {
  const auto colon = message.find(':');
  std::error_code ec;
  return colon != std::string::npos && colon > 0 && std::filesystem::is_regular_file(message.substr(0, colon), ec);
}

template <class Error, class Read>
void expect_clean(const std::string& path, Read&& read, bool other_files = false) {
  static const bool verbose = std::getenv("JG_FUZZ_VERBOSE") != nullptr;  // the replay driver's report
  try {
    read();
    if (verbose) std::fprintf(stderr, "  read\n");
  } catch (const Error& e) {
    const std::string message = e.what();
    if (verbose) std::fprintf(stderr, "  refused: %s\n", message.c_str());
    if (message.rfind(path, 0) != 0 && !(other_files && names_existing_file(message))) {
      finding("error message does not name the file", message);
    }
  } catch (const std::exception& e) {
    finding("exception of a foreign type", e.what());
  } catch (...) {
    finding("exception that is not a std::exception", "");
  }
}

}  // namespace jg::fuzz
