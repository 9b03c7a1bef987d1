#include "io/yaml_fields.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "io/utf8.hpp"

namespace jg::io {
namespace {
std::string where(const std::string& file, const YAML::Mark& m) {
  std::ostringstream os;
  os << file;
  if (!m.is_null()) {
    os << ':' << m.line + 1 << ':' << m.column + 1;
  }
  return os.str();
}

/// Nodes visited by check_keys before the file is refused: far above any robot, drive or
/// scenario file (models/panda.yaml, the largest shipped, has 320; a scenario has no lists
/// that grow with its length), reached only by aliases that expand exponentially (a "billion
/// laughs" document). It was 100,000: such a document then took 60 ms to refuse under the
/// sanitizers, and those inputs were most of the robot fuzzer's time.
constexpr std::size_t kMaxNodes = 10000;
/// Nesting depth refused before the recursion below can exhaust the stack: a robot or scenario
/// file nests a few levels; an alias inside its own anchor (`&a [*a]`) nests without end.
constexpr std::size_t kMaxDepth = 64;

/// yaml-cpp keeps both entries of a key written twice and reads the first: refused, naming
/// the second occurrence (`path` is the field path so far, e.g. "joints[1]"). Keys must be
/// plain scalars (a `? [list]` key cannot name a field).
void check_keys(const std::string& file, const YAML::Node& node, const std::string& path, std::size_t& visited,
                std::size_t depth = 0) {
  if (++visited > kMaxNodes) {
    throw FormatError(where(file, node.Mark()) + ": more than " + std::to_string(kMaxNodes) +
                      " YAML nodes (aliases expanding?); a robot or scenario file is far smaller");
  }
  if (depth > kMaxDepth) {
    throw FormatError(where(file, node.Mark()) + ": nested deeper than " + std::to_string(kMaxDepth) +
                      " levels (an alias inside its own anchor?); a robot or scenario file nests a few");
  }
  if (node.IsSequence()) {
    // Iterated, not indexed: yaml-cpp's size() of a sequence counts its entries each time,
    // so `i < node.size()` made a long list quadratic. (The robot fuzzer's 44 % in this
    // check was the node count of alias expansions, kMaxNodes above, not this.)
    std::size_t i = 0;
    for (const auto& item : node) check_keys(file, item, path + "[" + std::to_string(i++) + "]", visited, depth + 1);
  } else if (node.IsMap()) {
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) {
        throw FormatError(where(file, kv.first.Mark()) + ": field '" + path + "': a key must be plain text");
      }
      const std::string key = kv.first.Scalar();
      const std::string field = path.empty() ? key : path + "." + key;
      const auto [it, inserted] = seen.emplace(key, kv.first.Mark());
      if (!inserted) {
        throw FormatError(where(file, kv.first.Mark()) + ": field '" + field + "': duplicate key (first given on line " +
                          std::to_string(it->second.line + 1) + ")");
      }
      check_keys(file, kv.second, field, visited, depth + 1);
    }
  }
}
/// Whether `text` is UTF-8 (what YAML text is, and what the JSON written from it must be:
/// a Latin-1 name once failed only after a whole simulation, in nlohmann's dump).
bool is_utf8(const std::string& text) {
  for (std::size_t k = 0; k < text.size();) {
    const std::size_t len = utf8_sequence_length(text, k);
    if (len == 0) return false;
    k += len;
  }
  return true;
}
}  // namespace

YamlFields YamlFields::load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw FormatError(path + ": cannot open");
  }
  try {
    YAML::Node root = YAML::Load(in);
    if (!root.IsMap()) {
      throw FormatError(path + ": expected a mapping of keys at the top level");
    }
    std::size_t visited = 0;
    check_keys(path, root, "", visited);
    return YamlFields(path, root);
  } catch (const YAML::Exception& e) {
    throw FormatError(where(path, e.mark) + ": YAML syntax: " + e.msg);
  }
}

YamlFields::YamlFields(std::string file, YAML::Node node, std::string path)
    : file_(std::move(file)), node_(std::move(node)), path_(std::move(path)) {}

void YamlFields::fail(const std::string& key, const std::string& problem) const {
  YAML::Mark mark = node_.Mark();
  if (!key.empty() && node_.IsMap() && node_[key]) {
    mark = node_[key].Mark();
  }
  const std::string field = path_.empty() ? key : (key.empty() ? path_ : path_ + "." + key);
  throw FormatError(where(file_, mark) + ": field '" + field + "': " + problem);
}

void YamlFields::allow_only(std::initializer_list<const char*> allowed) const {
  if (!node_.IsMap()) {
    fail("", "expected a mapping");
  }
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      YamlFields(file_, node_, path_).fail(key, "unknown key (allowed: " + list + ")");
    }
  }
}

bool YamlFields::has(const std::string& key) const { return node_.IsMap() && node_[key] && !node_[key].IsNull(); }

YAML::Node YamlFields::get(const std::string& key) const {
  if (!has(key)) {
    fail(key, "missing");
  }
  return node_[key];
}

YamlFields YamlFields::child(const std::string& key) const {
  const YAML::Node n = get(key);
  if (!n.IsMap()) {
    fail(key, "expected a mapping");
  }
  return YamlFields(file_, n, path_.empty() ? key : path_ + "." + key);
}

std::vector<YamlFields> YamlFields::sequence(const std::string& key) const {
  const YAML::Node n = get(key);
  if (!n.IsSequence()) {
    fail(key, "expected a list");
  }
  std::vector<YamlFields> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    out.emplace_back(file_, n[i], (path_.empty() ? key : path_ + "." + key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

double YamlFields::to_number(const YAML::Node& n, const std::string& key) const {
  // At the value itself (a list's element "k_i[0]" is no key of this mapping: its line is
  // the element's, not the mapping's first).
  const auto fail_here = [&](const std::string& problem) {
    if (n.Mark().is_null()) fail(key, problem);
    const std::string field = path_.empty() ? key : path_ + "." + key;
    throw FormatError(where(file_, n.Mark()) + ": field '" + field + "': " + problem);
  };
  if (!n.IsScalar()) {
    fail_here("expected a number");
  }
  const std::string s = n.Scalar();
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
    fail_here("'" + s + "' is not a number in the unit the key names (SI)");
  }
  if (!std::isfinite(v)) {
    fail_here("'" + s + "' is not finite");
  }
  return v;
}

double YamlFields::number(const std::string& key) const { return to_number(get(key), key); }
double YamlFields::number(const std::string& key, double fallback) const {
  return has(key) ? number(key) : fallback;
}
long YamlFields::integer(const std::string& key, long fallback) const {
  if (!has(key)) {
    return fallback;
  }
  const double v = number(key);
  if (v != std::floor(v) || std::fabs(v) > 9e15) {
    fail(key, "expected a whole number");
  }
  return static_cast<long>(v);
}
bool YamlFields::boolean(const std::string& key, bool fallback) const {
  if (!has(key)) {
    return fallback;
  }
  const std::string s = get(key).Scalar();
  if (s == "true") return true;
  if (s == "false") return false;
  fail(key, "expected true or false, got '" + s + "'");
}
std::string YamlFields::text(const std::string& key) const {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) {
    fail(key, "expected text");
  }
  if (!is_utf8(n.Scalar())) fail(key, "bytes that are not UTF-8 text");
  return n.Scalar();
}
std::string YamlFields::text(const std::string& key, const std::string& fallback) const {
  return has(key) ? text(key) : fallback;
}
std::vector<double> YamlFields::numbers(const std::string& key) const {
  const YAML::Node n = get(key);
  if (!n.IsSequence()) {
    fail(key, "expected a list of numbers");
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(to_number(n[i], key + "[" + std::to_string(i) + "]"));
  return out;
}
std::vector<double> YamlFields::numbers(const std::string& key, std::size_t expected_size) const {
  auto v = numbers(key);
  if (v.size() != expected_size) {
    fail(key, "expected " + std::to_string(expected_size) + " values, got " + std::to_string(v.size()));
  }
  return v;
}

}  // namespace jg::io
