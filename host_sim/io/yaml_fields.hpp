// Strict reading of YAML documents: unknown keys, wrong types, non-finite numbers and
// missing fields are refused with "file:line:column: field 'path': problem".
#pragma once

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <vector>

#include "io/recording.hpp"

namespace jg::io {

class YamlFields {
 public:
  /// Loads a file; syntax errors become FormatError with the file's line and column.
  static YamlFields load_file(const std::string& path);
  YamlFields(std::string file, YAML::Node node, std::string path = "");

  /// Refuses any key not in `allowed` (catches typos and wrong units such as `duration_ms`).
  void allow_only(std::initializer_list<const char*> allowed) const;
  [[nodiscard]] bool has(const std::string& key) const;
  [[nodiscard]] YamlFields child(const std::string& key) const;  ///< must exist
  [[nodiscard]] std::vector<YamlFields> sequence(const std::string& key) const;  ///< must be a list

  [[nodiscard]] double number(const std::string& key) const;
  [[nodiscard]] double number(const std::string& key, double fallback) const;
  [[nodiscard]] long integer(const std::string& key, long fallback) const;
  [[nodiscard]] bool boolean(const std::string& key, bool fallback) const;
  [[nodiscard]] std::string text(const std::string& key) const;
  [[nodiscard]] std::string text(const std::string& key, const std::string& fallback) const;
  [[nodiscard]] std::vector<double> numbers(const std::string& key) const;
  [[nodiscard]] std::vector<double> numbers(const std::string& key, std::size_t expected_size) const;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] const YAML::Node& node() const { return node_; }

 private:
  [[nodiscard]] YAML::Node get(const std::string& key) const;
  [[nodiscard]] double to_number(const YAML::Node& n, const std::string& key) const;
  std::string file_;
  YAML::Node node_;
  std::string path_;
};

}  // namespace jg::io
