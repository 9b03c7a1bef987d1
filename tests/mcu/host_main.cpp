// The golden program on the host: jg_golden_host <input> <output>.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <vector>

#include "golden.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <input> <output>\n", argv[0]);
    return 2;
  }
  std::ifstream in(argv[1], std::ios::binary);
  const std::vector<std::uint8_t> input((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::uint8_t> output(1536 * 1024);
  std::size_t n = 0;
  const int rc = jg::golden::run(input.data(), input.size(), output.data(), output.size(), n);
  if (rc != 0) {
    std::fprintf(stderr, "golden: error %d\n", rc);
    return rc;
  }
  std::ofstream(argv[2], std::ios::binary).write(reinterpret_cast<const char*>(output.data()), static_cast<std::streamsize>(n));
  return 0;
}
