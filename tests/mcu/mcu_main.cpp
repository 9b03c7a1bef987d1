// The golden program on the emulated MCU: semihosting arguments "<input> <output>".
#include <cstring>

#include "golden.hpp"
#include "semihosting.hpp"

namespace {
std::uint8_t input[512 * 1024];
std::uint8_t output[1536 * 1024];
char cmdline[256];
}  // namespace

extern "C" int jg_app_main() {
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
