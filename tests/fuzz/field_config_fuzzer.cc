// libFuzzer target: the season and robot file loader (field_configs/loader.h) on arbitrary
// YAML text. Its contract: bad input throws ConfigError and nothing else; good input loads.
#include <cstddef>
#include <cstdint>
#include <string>

#include "field_configs/config_error.h"
#include "field_configs/loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Any other exception escapes and libFuzzer reports it as a crash.
  try {
    slamo::field::ParseSeasonConfig(text, "fuzz_season.yaml");
  } catch (const slamo::field::ConfigError&) {
  }
  try {
    slamo::field::ParseRobotConfig(text, "fuzz_robot.yaml");
  } catch (const slamo::field::ConfigError&) {
  }
  return 0;
}
