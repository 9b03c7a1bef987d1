// ARM semihosting (bkpt 0xAB on M-profile): file I/O on the host and the exit status,
// the few calls the emulated-MCU tests need. Caller-owned buffers, no heap.
#pragma once

#include <cstddef>
#include <cstdint>

namespace jg::mcu {

/// Opens a host file; mode "rb" or "wb". Returns a handle >= 0 or -1.
int open_file(const char* path, bool write);
int close_file(int handle);
/// Bytes not read (0 = all read).
std::size_t read_file(int handle, void* buffer, std::size_t bytes);
/// Bytes not written (0 = all written).
std::size_t write_file(int handle, const void* buffer, std::size_t bytes);
long file_length(int handle);
void write_text(const char* text);
/// Command line given to qemu (-semihosting-config arg=...); returns false if none.
bool command_line(char* buffer, std::size_t size);
[[noreturn]] void exit_with(int status);

}  // namespace jg::mcu
