// A reader's refusal of bad text: `text` is written to `path`, `read(path)` must throw, and
// its message must name the file and contain `needle` (the field or the reason).
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <fstream>
#include <string>

namespace jg::test {

template <class Read>
void expect_refused(const std::string& path, const std::string& text, const std::string& needle, Read&& read) {
  { std::ofstream(path) << text; }
  try {
    read(path);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace jg::test
