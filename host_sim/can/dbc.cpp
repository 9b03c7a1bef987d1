#include "can/dbc.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace jg::can {
namespace {

constexpr std::size_t kMaxDbcLine = 1024;

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

/// An unsigned number of at most 32 bits from the DBC or a capture (decimal or hex), or a
/// failure naming the file, line and field: std::stoul's "stoul" told the user nothing.
std::uint32_t number(const std::string& text, int base, const std::string& path, int line, const char* field) {
  std::uint64_t v = 0;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v, base);
  if (res.ec != std::errc() || res.ptr != text.data() + text.size() || v > 0xFFFFFFFFULL) {
    fail(path, line, std::string(field) + " '" + text.substr(0, 40) + "' is not a number of at most 32 bits");
  }
  return static_cast<std::uint32_t>(v);
}

/// Input quoted in a message: printable ASCII only (others as '?'), at most 80 characters,
/// so that a binary file does not write raw bytes to the terminal.
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text.substr(0, 80)) out.push_back(c >= 0x20 && c < 0x7F ? c : '?');
  if (text.size() > 80) out += "...";
  return out;
}

/// A finite decimal number (a signal's factor or offset, a capture's time stamp), or a
/// failure naming the file, line and field: strtod alone read "abc" as 0 and took "nan".
double real(const std::string& text, const std::string& path, int line, const char* field) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || errno == ERANGE || !std::isfinite(v)) {
    fail(path, line, std::string(field) + " '" + printable(text) + "' is not a finite number");
  }
  return v;
}

/// Whether every bit of the signal lies in a payload of `length` bytes: Intel signals run
/// up from the start bit; Motorola signals down from it within a byte, then on to the next
/// byte's bit 7 (the walk of decode_signal).
bool fits(const DbcSignal& s, unsigned length) {
  const std::uint64_t bits = 8ULL * length;
  if (s.start >= bits) return false;
  if (s.little_endian) return std::uint64_t{s.start} + s.size <= bits;
  std::uint64_t bit = s.start;
  for (unsigned b = 0; b + 1 < s.size; ++b) bit = (bit % 8 == 0) ? bit + 15 : bit - 1;
  return bit < bits;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// A hand-written scanner over one DBC line, matching the grammar the reader used to
/// express as regular expressions (ECMAScript: \s = space, \t, \n, \v, \f, \r; \w =
/// [A-Za-z0-9_]; \d = [0-9]). std::regex ran at about 150 lines/s under the fuzzer's
/// sanitizers and recursed per character; this is linear in the line, no recursion.
class Scanner {
 public:
  explicit Scanner(const std::string& text) : s_(text) {}
  /// Skips whitespace; returns how many characters it skipped.
  std::size_t spaces() {
    const std::size_t from = i_;
    while (i_ < s_.size() && is_space(s_[i_])) ++i_;
    return i_ - from;
  }
  bool literal(const char* text) {
    const std::string t(text);
    if (s_.compare(i_, t.size(), t) != 0) return false;
    i_ += t.size();
    return true;
  }
  /// One or more characters of `pred`, into `out`.
  template <class Pred>
  bool run(Pred pred, std::string& out) {
    const std::size_t from = i_;
    while (i_ < s_.size() && pred(s_[i_])) ++i_;
    out = s_.substr(from, i_ - from);
    return i_ > from;
  }
  bool digits(std::string& out) { return run([](char c) { return c >= '0' && c <= '9'; }, out); }
  bool word(std::string& out) {
    return run([](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }, out);
  }
  /// Everything up to (not including) `stop`, at least `min` characters, then `stop` itself.
  bool until(char stop, std::size_t min, std::string& out) {
    const std::size_t at = s_.find(stop, i_);
    if (at == std::string::npos || at - i_ < min) return false;
    out = s_.substr(i_, at - i_);
    i_ = at + 1;
    return true;
  }
  bool one_of(const char* set, char& out) {
    if (i_ >= s_.size() || std::strchr(set, s_[i_]) == nullptr || s_[i_] == '\0') return false;
    out = s_[i_++];
    return true;
  }
  /// The rest holds no line terminator (what `.*$` matched).
  [[nodiscard]] bool rest_is_one_line() const { return s_.find_first_of("\r\n", i_) == std::string::npos; }
  [[nodiscard]] bool at_end() const { return i_ == s_.size(); }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }
  const std::string& s_;
  std::size_t i_ = 0;
};

struct BoFields {
  std::string id, name, length, sender;
};
/// BO_ <id> <name>: <length> <sender>
bool scan_bo(const std::string& text, BoFields& f) {
  Scanner c(text);
  return c.literal("BO_") && c.spaces() > 0 && c.digits(f.id) && c.spaces() > 0 && c.word(f.name) && (c.spaces(), c.literal(":")) &&
         (c.spaces(), c.digits(f.length)) && c.spaces() > 0 && c.word(f.sender) && (c.spaces(), c.at_end());
}

struct SgFields {
  std::string name, start, size, factor, offset, unit;
  char order = '1', sign = '+';
};
/// SG_ <name> : <start>|<size>@<1|0><+|-> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
bool scan_sg(const std::string& text, SgFields& f) {
  Scanner c(text);
  std::string range;
  c.spaces();
  return c.literal("SG_") && c.spaces() > 0 && c.word(f.name) && (c.spaces(), c.literal(":")) && (c.spaces(), c.digits(f.start)) &&
         c.literal("|") && c.digits(f.size) && c.literal("@") && c.one_of("01", f.order) && c.one_of("+-", f.sign) &&
         (c.spaces(), c.literal("(")) && c.until(',', 1, f.factor) && c.until(')', 1, f.offset) && (c.spaces(), c.literal("[")) &&
         c.until(']', 0, range) && (c.spaces(), c.literal("\"")) && c.until('"', 0, f.unit) && c.rest_is_one_line();
}

/// BA_ "VFrameFormat" BO_ <id> <value>;
bool scan_ba(const std::string& text, std::string& id, std::string& value) {
  Scanner c(text);
  return c.literal("BA_") && c.spaces() > 0 && c.literal("\"VFrameFormat\"") && c.spaces() > 0 && c.literal("BO_") && c.spaces() > 0 &&
         c.digits(id) && c.spaces() > 0 && c.digits(value) && (c.spaces(), c.literal(";")) && (c.spaces(), c.at_end());
}

/// A signal definition: "SG_" and a space after any indentation (a tab or two spaces were
/// once skipped silently; SG_MUL_VAL_ and other keywords are not signals).
bool is_signal_line(const std::string& text) {
  const std::size_t at = text.find_first_not_of(" \t\v\f");
  return at != std::string::npos && text.compare(at, 3, "SG_") == 0 && (at + 3 == text.size() ||
         std::strchr(" \t\v\f\r", text[at + 3]) != nullptr);
}

}  // namespace

Dbc read_dbc(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open the DBC file");
  Dbc dbc;
  DbcMessage* current = nullptr;
  std::string text;
  int line = 0;
  while (std::getline(f, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    // A DBC line is a message or a signal definition, far shorter than this (a 40 kB line
    // once overflowed the stack of the std::regex this reader used).
    if (text.size() > kMaxDbcLine) {
      fail(path, line, "line of " + std::to_string(text.size()) + " characters (at most " + std::to_string(kMaxDbcLine) + ")");
    }
    BoFields bo;
    SgFields sg;
    std::string ba_id, ba_value;
    if (scan_bo(text, bo)) {
      DbcMessage msg;
      msg.id = number(bo.id, 10, path, line, "message identifier");
      msg.name = bo.name;
      msg.length = number(bo.length, 10, path, line, "message length");
      msg.sender = bo.sender;
      if (msg.length > 64) fail(path, line, "message " + msg.name + ": length " + std::to_string(msg.length) + " > 64");
      if (dbc.messages.count(msg.id) != 0) fail(path, line, "identifier " + std::to_string(msg.id) + " defined twice");
      current = &(dbc.messages[msg.id] = msg);
    } else if (is_signal_line(text)) {
      if (current == nullptr) fail(path, line, "signal outside a message");
      if (!scan_sg(text, sg)) fail(path, line, "cannot read the signal definition");
      DbcSignal s;
      s.name = sg.name;
      s.start = number(sg.start, 10, path, line, "signal start bit");
      s.size = number(sg.size, 10, path, line, "signal size");
      s.little_endian = sg.order == '1';
      s.is_signed = sg.sign == '-';
      s.factor = real(sg.factor, path, line, "signal factor");
      s.offset = real(sg.offset, path, line, "signal offset");
      s.unit = sg.unit;
      if (s.size == 0 || s.size > 64) fail(path, line, "signal " + s.name + ": size " + std::to_string(s.size) + " not in 1..64");
      // Checked for both byte orders (a start bit near 2^32 wrapped the old Intel-only sum).
      if (!fits(s, current->length)) {
        fail(path, line, "signal " + s.name + " lies outside the message's " + std::to_string(current->length) + " bytes");
      }
      current->signals.push_back(s);
    } else if (scan_ba(text, ba_id, ba_value)) {
      const auto id = number(ba_id, 10, path, line, "VFrameFormat identifier");
      auto it = dbc.messages.find(id);
      if (it == dbc.messages.end()) fail(path, line, "VFrameFormat for unknown message " + std::to_string(id));
      it->second.fd = number(ba_value, 10, path, line, "VFrameFormat value") >= 14;
    } else if (text.rfind("BO_ ", 0) == 0) {
      fail(path, line, "cannot read the message definition");
    } else if (!text.empty() && text[0] != ' ') {
      current = nullptr;
    }
  }
  if (dbc.messages.empty()) throw std::runtime_error(path + ": no messages (BO_) found");
  return dbc;
}

double decode_signal(const DbcSignal& s, const std::uint8_t* data, unsigned length) {
  std::uint64_t raw = 0;
  if (s.little_endian) {
    for (unsigned b = 0; b < s.size; ++b) {
      const unsigned bit = s.start + b;
      if (bit / 8 < length && ((data[bit / 8] >> (bit % 8)) & 1U) != 0U) raw |= std::uint64_t{1} << b;
    }
  } else {
    // Motorola: start is the most significant bit, counting down within a byte, then on
    // to the next byte's bit 7.
    unsigned bit = s.start;
    for (unsigned b = 0; b < s.size; ++b) {
      if (bit / 8 < length && ((data[bit / 8] >> (bit % 8)) & 1U) != 0U) raw |= std::uint64_t{1} << (s.size - 1 - b);
      bit = (bit % 8 == 0) ? bit + 15 : bit - 1;
    }
  }
  double v = static_cast<double>(raw);
  if (s.is_signed && s.size < 64 && (raw >> (s.size - 1)) != 0U) v -= static_cast<double>(std::uint64_t{1} << s.size);
  return v * s.factor + s.offset;
}

std::vector<CapturedFrame> read_candump_log(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open the capture");
  std::vector<CapturedFrame> out;
  std::string text;
  int line = 0;
  while (std::getline(f, text)) {
    ++line;
    if (text.empty()) continue;
    std::istringstream in(text);
    std::string stamp, iface, body;
    if (!(in >> stamp >> iface >> body) || stamp.size() < 3 || stamp.front() != '(' || stamp.back() != ')') {
      fail(path, line, "not a candump -L line: '" + printable(text) + "'");
    }
    CapturedFrame c;
    c.t = real(stamp.substr(1, stamp.size() - 2), path, line, "time stamp");
    c.interface = iface;
    const auto hash = body.find('#');
    if (hash == std::string::npos || hash == 0) fail(path, line, "frame without '#': '" + printable(body) + "'");
    const std::string id = body.substr(0, hash);
    for (const char ch : id) {
      if (hex_digit(ch) < 0) fail(path, line, "identifier '" + printable(id) + "' is not hexadecimal");
    }
    c.frame.id = number(id, 16, path, line, "identifier");
    c.frame.extended = id.size() > 3;
    // candump writes 3 hex digits for an 11-bit identifier and 8 for a 29-bit one.
    if (c.frame.id > (c.frame.extended ? 0x1FFFFFFFU : 0x7FFU)) {
      fail(path, line, "identifier '" + id + "' is beyond " + (c.frame.extended ? "29" : "11") + " bits");
    }
    std::size_t pos = hash + 1;
    if (pos < body.size() && body[pos] == '#') {
      c.frame.fd = true;
      if (pos + 1 >= body.size() || hex_digit(body[pos + 1]) < 0) fail(path, line, "CAN FD frame without its flags nibble after '##'");
      pos += 2;  // '#' and the flags nibble
    } else if (pos < body.size() && body[pos] == 'R') {
      fail(path, line, "remote frames are not part of the joint protocol");
    }
    const std::string hex = pos <= body.size() ? body.substr(pos) : std::string();
    if (hex.size() % 2 != 0 || hex.size() / 2 > 64) fail(path, line, "payload '" + printable(hex) + "' is not whole bytes (at most 64)");
    for (std::size_t i = 0; i < hex.size(); i += 2) {
      const int hi = hex_digit(hex[i]), lo = hex_digit(hex[i + 1]);
      if (hi < 0 || lo < 0) fail(path, line, "payload byte '" + printable(hex.substr(i, 2)) + "' is not hexadecimal");
      c.frame.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
    }
    c.frame.length = static_cast<std::uint8_t>(hex.size() / 2);
    if (!hal::valid_length(c.frame.length, c.frame.fd)) fail(path, line, "length " + std::to_string(c.frame.length) + " is not a CAN length");
    out.push_back(c);
  }
  return out;
}

}  // namespace jg::can
