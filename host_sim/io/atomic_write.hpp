// One output writer for every file the tools write: to a temporary file in the same folder,
// every write checked, then renamed into place. A failure (a missing folder, a full disk, a
// directory in the way) throws naming the path and leaves neither a partial file nor the
// temporary one: no command reports success without its file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace jg::io {

/// Writes `text` to `path` atomically; throws io::FormatError naming the path on failure.
void write_text_atomic(const std::string& path, const std::string& text);

/// JSON (2-space indent, invalid UTF-8 replaced) through write_text_atomic.
void write_json_atomic(const std::string& path, const nlohmann::json& j);

}  // namespace jg::io
