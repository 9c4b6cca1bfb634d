#include "platform/rawlog_guard.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <new>
#include <sstream>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/poses/CPosePDFParticles.h>
#include <mrpt/serialization/CArchive.h>

#if defined(__SANITIZE_ADDRESS__)
#define SLAMO_RAWLOG_GUARD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SLAMO_RAWLOG_GUARD_ASAN 1
#endif
#endif

namespace slamo::platform {
namespace {

// What one record may allocate in the child beyond what the process already maps: a record is
// one observation (a 640x480 RGB-D frame is about 1.5 MB), so a request for more is a corrupt
// size. (Not under AddressSanitizer, whose shadow memory fills the address space.)
constexpr uint64_t kChildBudgetBytes = 1ull << 30;
constexpr int kExitTooBig = 5;

// MRPT rebuilds an odometry movement of the "Thrun" motion model by drawing as many particles
// as a uint32 in the record says (CActionRobotMovement2D::serializeFrom calls
// computeFromOdometry), so a record of under 200 bytes can ask for billions: 15 million take
// about 4 s and 700 MB (replay_rawlog_fuzzer's slow inputs). MRPT's default is 300; more than
// this is a corrupt count, and the file is refused instead of being read again in-process.
constexpr size_t kMaxParticles = 100000;
constexpr int kExitTooManyParticles = 6;

// The most particles that a robot movement in `object` holds (nested action collections and
// rawlogs included).
size_t MostParticles(const mrpt::serialization::CSerializable* object) {
  using namespace mrpt::obs;  // NOLINT(build/namespaces): the MRPT classes, briefly
  size_t most = 0;
  if (const auto* move = dynamic_cast<const CActionRobotMovement2D*>(object)) {
    if (const auto* particles =
            dynamic_cast<const mrpt::poses::CPosePDFParticles*>(move->poseChange.get())) {
      most = particles->size();
    }
  } else if (const auto* actions = dynamic_cast<const CActionCollection*>(object)) {
    for (const auto& action : *actions) most = std::max(most, MostParticles(action.get()));
  } else if (const auto* rawlog = dynamic_cast<const CRawlog*>(object)) {
    for (const auto& entry : *rawlog) most = std::max(most, MostParticles(entry.get()));
  }
  return most;
}

void LimitAddressSpace() {
#ifndef SLAMO_RAWLOG_GUARD_ASAN
  uint64_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  if (pages == 0) return;
  const uint64_t limit = pages * static_cast<uint64_t>(::sysconf(_SC_PAGESIZE)) + kChildBudgetBytes;
  rlimit current{};
  if (::getrlimit(RLIMIT_AS, &current) != 0) return;
  if (current.rlim_cur != RLIM_INFINITY && current.rlim_cur < limit) return;
  const rlimit lowered{limit, current.rlim_max};
  ::setrlimit(RLIMIT_AS, &lowered);
#endif
}

// The child: reads to the end, telling the parent each record's number as it starts it.
[[noreturn]] void ReadInChild(const std::string& path, int report_fd, unsigned timeout_s) {
  // Quiet, and no sanitizer or crash handler of the parent's: a crash just ends the child.
  const int devnull = ::open("/dev/null", O_WRONLY);
  if (devnull >= 0) {
    ::dup2(devnull, STDOUT_FILENO);
    ::dup2(devnull, STDERR_FILENO);
  }
  // SIGALRM too: a host that handles it (libFuzzer does, for its -timeout) would otherwise
  // swallow the backstop alarm below. The parent's deadline is what bounds the read.
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGALRM})
    std::signal(sig, SIG_DFL);
  sigset_t alarm_only;
  sigemptyset(&alarm_only);
  sigaddset(&alarm_only, SIGALRM);
  ::sigprocmask(SIG_UNBLOCK, &alarm_only, nullptr);
  ::alarm(timeout_s);
  LimitAddressSpace();
  try {
    mrpt::io::CFileGZInputStream file;
    if (!file.open(path)) ::_exit(3);
    auto archive = mrpt::serialization::archiveFrom(file);
    for (uint32_t record = 1;; ++record) {
      if (::write(report_fd, &record, sizeof(record)) != sizeof(record)) ::_exit(4);
      try {
        const auto object = archive.ReadObject();
        if (MostParticles(object.get()) > kMaxParticles) ::_exit(kExitTooManyParticles);
      } catch (const mrpt::serialization::CExceptionEOF&) {
        ::_exit(0);
      }
    }
  } catch (const std::bad_alloc&) {
    ::_exit(kExitTooBig);
  } catch (...) {
    ::_exit(3);  // an error MRPT reports: the caller's reader names it
  }
}

}  // namespace

std::string MrptErrorGist(const std::string& text) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("====", 0) == 0 || line.rfind("Call stack", 0) == 0) continue;
    for (const char* label : {"Message:", "Location:"}) {
      if (line.rfind(label, 0) == 0) line.erase(0, std::string(label).size());
    }
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    // A garbled file yields garbled class names: keep the message printable and short.
    std::string gist = line.substr(first, 160);
    for (char& c : gist) {
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    }
    return gist;
  }
  return "no message";
}

std::optional<std::string> CheckRawlogInChildProcess(const std::string& path, double timeout_s) {
  int fds[2];
  if (::pipe(fds) != 0) return std::nullopt;  // cannot isolate: read in-process as before
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return std::nullopt;
  }
  if (pid == 0) {
    ::close(fds[0]);
    // A backstop should this process die first; the deadline below comes before it.
    ReadInChild(path, fds[1], static_cast<unsigned>(std::ceil(std::max(timeout_s, 0.0))) + 1);
  }
  ::close(fds[1]);
  // The deadline is kept here, not by a signal in the child: a SIGALRM handler or ignored
  // SIGALRM that the child inherits (libFuzzer handles SIGALRM) would let it run on.
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(std::max(timeout_s, 0.0)));
  bool timed_out = false;
  uint32_t record = 0, got = 0;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd ready{fds[0], POLLIN, 0};
    const int n_ready = ::poll(&ready, 1, static_cast<int>(std::min<int64_t>(left, 1000)));
    if (n_ready == 0 || (n_ready < 0 && errno == EINTR)) continue;
    if (n_ready < 0) {  // cannot wait (poll failed): stop the child, as at the deadline
      timed_out = true;
      break;
    }
    const ssize_t n = ::read(fds[0], &got, sizeof(got));
    if (n == static_cast<ssize_t>(sizeof(got))) {
      record = got;
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      break;  // the child closed the pipe (ended)
    }
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return std::nullopt;
  }
  const std::string where = " reading record " + std::to_string(record);
  char seconds[32];
  std::snprintf(seconds, sizeof(seconds), "%g", timeout_s);
  if (timed_out) {
    return std::string("MRPT's rawlog deserialiser took more than ") + seconds +
           " s (a corrupt count?)" + where;
  }
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code == 0 || code == 3) return std::nullopt;
    if (code == kExitTooManyParticles) {
      return "a robot movement asks MRPT's rawlog deserialiser to draw more than " +
             std::to_string(kMaxParticles) + " particles (a corrupt count?)" + where;
    }
    if (code == kExitTooBig) {
      return "a record asks MRPT's rawlog deserialiser for more than " +
             std::to_string(kChildBudgetBytes >> 20) + " MiB (a corrupt size?)" + where;
    }
    return "MRPT's rawlog deserialiser ended the reading process (exit " + std::to_string(code) +
           ")" + where;
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGALRM) {
      return std::string("MRPT's rawlog deserialiser hung (more than ") + seconds + " s)" + where;
    }
    const char* name = sigabbrev_np(sig);
    return std::string("MRPT's rawlog deserialiser crashed (SIG") + (name ? name : "?") + ")" +
           where;
  }
  return std::nullopt;
}

bool StoredBool(const bool& flag) {
  unsigned char byte = 0;
  static_assert(sizeof(bool) == sizeof(byte), "a bool is one byte");
  std::memcpy(&byte, &flag, sizeof(byte));
  return byte != 0;
}

}  // namespace slamo::platform
