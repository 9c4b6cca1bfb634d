// Shared helpers: shipped config text, and edits of it that make one mistake each.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "field_configs/loader.h"

namespace slamo::field::testing {

inline std::string ReadShipped(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// `text` with the first occurrence of `from` replaced by `to`; fails the test if absent.
inline std::string Edit(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test edit target not found: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// 1-based line of the first occurrence of `needle`.
inline int LineOf(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  int line = 1;
  for (size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

}  // namespace slamo::field::testing
