// MRPT's rawlog deserialisers trust the file: a corrupt record can crash them (a SEGV in
// CActionRobotMovement2D::serializeFrom, tests/fuzz/known_crashes/), hang them or make them
// allocate gigabytes or draw millions of samples, inside MRPT, before any of our code sees
// the object. So every rawlog is first read to its end in a child process; only a file the
// child read without crashing, in time, is read again in this process. Costs one more pass
// over the file (a 36 MB rawlog: about a second); a crash or hang costs the child, never the
// program.
#pragma once

#include <optional>
#include <string>

namespace slamo::platform {

// Reads every record of the rawlog at `path` with MRPT in a child process. Nothing when the
// child reached the end or stopped on an error MRPT reports as an exception (the caller's own
// reader then reports it); otherwise what happened, for the caller's error: "MRPT's rawlog
// deserialiser crashed (SIGSEGV) reading record 3", took more than timeout_s (this process
// keeps the deadline and kills the child, whatever the child's signal handlers), asked for
// more than 1 GiB for one record (a corrupt size: the child's address space is limited,
// except under AddressSanitizer), or made MRPT draw more than 100000 particles for one robot
// movement (a corrupt count in the record; MRPT's default is 300).
std::optional<std::string> CheckRawlogInChildProcess(const std::string& path,
                                                     double timeout_s = 120.0);

// The gist of an MRPT exception message, for an error of ours: MRPT's have a banner, then
// `Message:` and `Location:` lines (either may be empty), then a call stack. The first line
// with content, printable and at most 160 characters (a garbled file yields garbled class
// names); "no message" when there is none.
std::string MrptErrorGist(const std::string& what);

// A bool member as MRPT deserialised it. MRPT reads the file's byte straight into the bool, so
// a corrupt rawlog can leave a value other than 0 or 1 there, and loading such a bool is
// undefined behaviour (UBSan: "load of value 78, which is not a valid value for type 'bool'").
// This reads the byte instead: any non-zero byte is true. Use it for every bool a rawlog set.
bool StoredBool(const bool& flag);

}  // namespace slamo::platform
