#include "can/dbc.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <regex>
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

}  // namespace

Dbc read_dbc(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open the DBC file");
  // BO_ <id> <name>: <length> <sender>
  const std::regex bo(R"(^BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+)\s+(\w+)\s*$)");
  // SG_ <name> : <start>|<size>@<1|0><+|-> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
  const std::regex sg(R"(^\s*SG_\s+(\w+)\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(([^,]+),([^)]+)\)\s*\[[^\]]*\]\s*\"([^\"]*)\".*$)");
  const std::regex ba(R"(^BA_\s+\"VFrameFormat\"\s+BO_\s+(\d+)\s+(\d+)\s*;\s*$)");
  Dbc dbc;
  DbcMessage* current = nullptr;
  std::string text;
  int line = 0;
  while (std::getline(f, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    // std::regex matches by recursion: a line of tens of kB overflows the stack. A DBC line
    // is a message or a signal definition, far shorter than this.
    if (text.size() > kMaxDbcLine) {
      fail(path, line, "line of " + std::to_string(text.size()) + " characters (at most " + std::to_string(kMaxDbcLine) + ")");
    }
    std::smatch m;
    if (std::regex_match(text, m, bo)) {
      DbcMessage msg;
      msg.id = number(m[1], 10, path, line, "message identifier");
      msg.name = m[2];
      msg.length = number(m[3], 10, path, line, "message length");
      msg.sender = m[4];
      if (msg.length > 64) fail(path, line, "message " + msg.name + ": length " + std::to_string(msg.length) + " > 64");
      if (dbc.messages.count(msg.id) != 0) fail(path, line, "identifier " + std::to_string(msg.id) + " defined twice");
      current = &(dbc.messages[msg.id] = msg);
    } else if (text.rfind(" SG_", 0) == 0 || text.rfind("SG_", 0) == 0) {
      if (current == nullptr) fail(path, line, "signal outside a message");
      if (!std::regex_match(text, m, sg)) fail(path, line, "cannot read the signal definition");
      DbcSignal s;
      s.name = m[1];
      s.start = number(m[2], 10, path, line, "signal start bit");
      s.size = number(m[3], 10, path, line, "signal size");
      s.little_endian = m[4] == "1";
      s.is_signed = m[5] == "-";
      s.factor = real(m[6], path, line, "signal factor");
      s.offset = real(m[7], path, line, "signal offset");
      s.unit = m[8];
      if (s.size == 0 || s.size > 64) fail(path, line, "signal " + s.name + ": size " + std::to_string(s.size) + " not in 1..64");
      // Checked for both byte orders (a start bit near 2^32 wrapped the old Intel-only sum).
      if (!fits(s, current->length)) {
        fail(path, line, "signal " + s.name + " lies outside the message's " + std::to_string(current->length) + " bytes");
      }
      current->signals.push_back(s);
    } else if (std::regex_match(text, m, ba)) {
      const auto id = number(m[1], 10, path, line, "VFrameFormat identifier");
      auto it = dbc.messages.find(id);
      if (it == dbc.messages.end()) fail(path, line, "VFrameFormat for unknown message " + std::to_string(id));
      it->second.fd = number(m[2], 10, path, line, "VFrameFormat value") >= 14;
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
