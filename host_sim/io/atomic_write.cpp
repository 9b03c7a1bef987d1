#include "io/atomic_write.hpp"

#include <filesystem>
#include <fstream>

#include "io/recording.hpp"

namespace jg::io {

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::filesystem::path target(path);
  if (std::filesystem::is_directory(target)) throw FormatError(path + ": is a directory, not a file to write");
  const std::filesystem::path tmp = target.string() + ".tmp";
  std::error_code ec;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw FormatError(path + ": cannot write (does its folder exist?)");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(tmp, ec);
      throw FormatError(path + ": write failed");
    }
  }
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw FormatError(path + ": cannot write: " + ec.message());
  }
}

void write_json_atomic(const std::string& path, const nlohmann::json& j) {
  write_text_atomic(path, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace jg::io
