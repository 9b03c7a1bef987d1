#include "semihosting.hpp"

#include <cstring>

namespace jg::mcu {
namespace {
enum Op : std::uint32_t {
  kOpen = 0x01, kClose = 0x02, kWrite0 = 0x04, kWrite = 0x05, kRead = 0x06, kFlen = 0x0C,
  kGetCmdline = 0x15, kExit = 0x18, kExitExtended = 0x20
};

std::uint32_t call(std::uint32_t op, const void* arg) {
  std::uint32_t result = 0;
  __asm volatile("mov r0, %1\n mov r1, %2\n bkpt 0xAB\n mov %0, r0"
                 : "=r"(result)
                 : "r"(op), "r"(arg)
                 : "r0", "r1", "memory");
  return result;
}
}  // namespace

int open_file(const char* path, bool write) {
  // Mode 1 = "rb", 5 = "wb" (semihosting's fopen mode table).
  const std::uint32_t block[3] = {static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(path)), write ? 5U : 1U,
                                  static_cast<std::uint32_t>(std::strlen(path))};
  return static_cast<int>(call(kOpen, block));
}
int close_file(int handle) {
  const std::uint32_t block[1] = {static_cast<std::uint32_t>(handle)};
  return static_cast<int>(call(kClose, block));
}
std::size_t read_file(int handle, void* buffer, std::size_t bytes) {
  const std::uint32_t block[3] = {static_cast<std::uint32_t>(handle),
                                  static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(buffer)),
                                  static_cast<std::uint32_t>(bytes)};
  return call(kRead, block);
}
std::size_t write_file(int handle, const void* buffer, std::size_t bytes) {
  const std::uint32_t block[3] = {static_cast<std::uint32_t>(handle),
                                  static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(buffer)),
                                  static_cast<std::uint32_t>(bytes)};
  return call(kWrite, block);
}
long file_length(int handle) {
  const std::uint32_t block[1] = {static_cast<std::uint32_t>(handle)};
  const std::int32_t length = static_cast<std::int32_t>(call(kFlen, block));
  return length;
}
void write_text(const char* text) { (void)call(kWrite0, text); }
bool command_line(char* buffer, std::size_t size) {
  std::uint32_t block[2] = {static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(buffer)),
                            static_cast<std::uint32_t>(size)};
  return call(kGetCmdline, block) == 0U;
}
void exit_with(int status) {
  // SYS_EXIT_EXTENDED: ADP_Stopped_ApplicationExit (0x20026) with the status code.
  const std::uint32_t block[2] = {0x20026U, static_cast<std::uint32_t>(status)};
  (void)call(kExitExtended, block);
  const std::uintptr_t reason = 0x20026U;
  (void)call(kExit, reinterpret_cast<const void*>(reason));
  for (;;) {
  }
}

}  // namespace jg::mcu
