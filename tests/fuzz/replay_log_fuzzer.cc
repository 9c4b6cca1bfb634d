// libFuzzer targets: the replay-log readers (mapping/replay_log.h). The readers take a path,
// so the input goes to a per-process temporary file. Built twice: SLAMO_FUZZ_RAWLOG=0 reads
// the text format, =1 an MRPT rawlog. Contract: a bad log throws ReplayLogError and nothing
// else; a good one gives events in time order with finite numbers.
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "mapping/replay_log.h"

namespace {

const std::string& TempPath() {
  static const std::string path =
      "/tmp/slamo_fuzz_" + std::to_string(::getpid()) + (SLAMO_FUZZ_RAWLOG ? ".rawlog" : ".log");
  return path;
}

}  // namespace

// MRPT's deserialisers size containers from counts in the file before reading the elements,
// so a corrupt rawlog of a few hundred bytes can ask for gigabytes (found by this target).
// Under a 2 GiB address-space limit such a request fails, and the contract is that ReadRawlog
// turns the std::bad_alloc into a ReplayLogError. (This target is built without ASan, whose
// allocator aborts instead of throwing.)
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (SLAMO_FUZZ_RAWLOG) {
    const rlimit limit{2ul << 30, 2ul << 30};
    setrlimit(RLIMIT_AS, &limit);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = TempPath();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  // An input that hangs MRPT's deserialiser must be reported well inside libFuzzer's
  // -timeout (10 s in scripts/fuzz), not after the readers' default two minutes.
  slamo::mapping::ReplayLogOptions options;
  options.rawlog_check_timeout_s = 2.0;
  try {
    const slamo::mapping::ReplayLog log = SLAMO_FUZZ_RAWLOG
                                              ? slamo::mapping::ReadRawlog(path, options)
                                              : slamo::mapping::ReadTextLog(path, options);
    double last_t = -INFINITY;
    for (const slamo::mapping::LogEvent& e : log.events) {
      if (!(e.t_s >= last_t)) std::abort();  // time order (text format promises it)
      if (!SLAMO_FUZZ_RAWLOG) last_t = e.t_s;
      if (e.is_odometry()) {
        const auto& o = e.odometry();
        if (!std::isfinite(o.dx_m) || !std::isfinite(o.dy_m) || !std::isfinite(o.dtheta_rad)) {
          if (!SLAMO_FUZZ_RAWLOG) std::abort();
        }
      }
    }
  } catch (const slamo::mapping::ReplayLogError&) {
  }
  return 0;
}
