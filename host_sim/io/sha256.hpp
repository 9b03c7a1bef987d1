// SHA-256 (FIPS 180-4) of a byte string, for provenance: an output names the exact input it
// was made from, checkable with `sha256sum`.
#pragma once

#include <string>

namespace jg::io {

/// Lower-case hex digest (64 characters) of `bytes`.
[[nodiscard]] std::string sha256_hex(const std::string& bytes);

}  // namespace jg::io
