// Reading a URDF with urdfdom without letting the file's text reach printf: urdfdom hands
// its messages (holding the user's text) to console_bridge as the printf format, so a
// `%s` or `%n` in a value crashed or aborted. Here urdfdom only parses with logging on a
// copy whose '%' are replaced (its complaints are captured and refuse the file), then
// parses the real text with logging off. The values the import uses are then checked:
// finite, masses >= 0, physical inertias. Errors are io::FormatError naming the file and
// the link or joint and field.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <string>

namespace jg::robot {
urdf::ModelInterfaceSharedPtr read_urdf(const std::string& path);
}
