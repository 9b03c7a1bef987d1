// The golden program on the emulated MCU: semihosting arguments "<input> <output>".
#include <cstring>

#include "golden.hpp"
#include "jointguard/protocol/frames.hpp"
#include "semihosting.hpp"

namespace {
/// The MCU's wire conversions (frames.hpp: one VFP sequence in round-toward-minus-infinity
/// mode, one fixed-point VCVT) against the portable C++ ones (float_to_wire, equal to
/// q16::from_float on a dense host sweep in tests/can; to_float) on this FPU: every 251st
/// float bit pattern (NaNs, infinities, subnormals included), the ties k + 0.5 and the
/// saturation edges around +/-2^31, and every 251st raw word. Returns the mismatches.
#if JG_WIRE_FLOAT_ASM
unsigned wire_self_check() {
  unsigned bad = 0;
  const auto check_float = [&bad](float v) {
    std::uint8_t fast[4] = {};
    jg::protocol::detail::floats_to_wire<1>(v, static_cast<std::uint8_t*>(fast));
    if (jg::protocol::detail::get_i32(static_cast<const std::uint8_t*>(fast)) != jg::protocol::detail::float_to_wire(v)) {
      ++bad;
    }
  };
  for (std::uint64_t bits = 0; bits <= 0xFFFFFFFFULL; bits += 251U) {
    const auto b = static_cast<std::uint32_t>(bits);
    float v = 0.0F;
    std::memcpy(&v, &b, 4);
    check_float(v);
  }
  for (int k = -70000; k <= 70000; ++k) {
    check_float((static_cast<float>(k) + 0.5F) / 65536.0F);  // exact ties of the rounding
  }
  for (const float edge : {2147483520.0F, 2147483648.0F, 2147483392.0F, 4294967296.0F}) {
    check_float(edge / 65536.0F);
    check_float(-edge / 65536.0F);
  }
  for (std::uint64_t raw = 0; raw <= 0xFFFFFFFFULL; raw += 251U) {
    const auto r = static_cast<std::int32_t>(static_cast<std::uint32_t>(raw));
    const float fast = jg::protocol::detail::wire_to_float(r);
    const float ref = jg::q16::from_raw(r).to_float();
    if (std::memcmp(&fast, &ref, 4) != 0) {
      ++bad;
    }
  }
  return bad;
}
#else
unsigned wire_self_check() { return 0U; }  // the portable conversions are the only ones
#endif

std::uint8_t input[512 * 1024];
std::uint8_t output[1536 * 1024];
char cmdline[256];
}  // namespace

extern "C" int jg_app_main() {
  if (wire_self_check() != 0U) {
    jg::mcu::write_text("golden: the MCU's float wire conversion differs from the portable one\n");
    return 17;
  }
  if (!jg::mcu::command_line(cmdline, sizeof cmdline)) {
    jg::mcu::write_text("golden: no command line\n");
    return 10;
  }
  // argv[0] is the program name; then input and output paths.
  char* args[3] = {nullptr, nullptr, nullptr};
  int argc = 0;
  for (char* p = cmdline; *p != '\0' && argc < 3;) {
    while (*p == ' ') *p++ = '\0';
    if (*p == '\0') break;
    args[argc++] = p;
    while (*p != '\0' && *p != ' ') ++p;
  }
  if (argc < 3) {
    jg::mcu::write_text("golden: usage: golden.elf <input> <output>\n");
    return 11;
  }
  const int in = jg::mcu::open_file(args[1], false);
  if (in < 0) return 12;
  const long len = jg::mcu::file_length(in);
  if (len <= 0 || static_cast<unsigned long>(len) > sizeof input) return 13;
  if (jg::mcu::read_file(in, input, static_cast<std::size_t>(len)) != 0U) return 14;
  (void)jg::mcu::close_file(in);
  std::size_t out_len = 0;
  const int rc = jg::golden::run(input, static_cast<std::size_t>(len), output, sizeof output, out_len);
  if (rc != 0) return rc;
  const int out = jg::mcu::open_file(args[2], true);
  if (out < 0) return 15;
  if (jg::mcu::write_file(out, output, out_len) != 0U) return 16;
  (void)jg::mcu::close_file(out);
  jg::mcu::write_text("golden: done\n");
  return 0;
}
