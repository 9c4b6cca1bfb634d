// The one exception type for bad configuration: it names the file, the line and column, the
// key path and what was expected. Thrown at start-up only; `slamo` prints it and exits 2.
#pragma once

#include <stdexcept>
#include <string>

namespace slamo::field {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string file, int line, int column, std::string key_path, std::string expected);

  const std::string& file() const { return file_; }
  int line() const { return line_; }  // 1-based; 0 when unknown
  int column() const { return column_; }
  const std::string& key_path() const { return key_path_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string key_path_;
  std::string expected_;
};

}  // namespace slamo::field
