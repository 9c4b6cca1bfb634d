// The one MRPT rawlog reader: opens a rawlog safely and hands out its records in order,
// flattened. Both rawlog readers of slamo use it (recordings: recording.cc; replay logs:
// mapping/replay_log.cc) and keep only what is theirs: which observations they accept and how
// they convert them, and their own error type (they turn RawlogError into it).
//
// Opening reads the whole file in a child process first (rawlog_guard.h), so a record that
// crashes or hangs MRPT's deserialiser is an error here, not a crash. Then the records are
// read one at a time as the entries are asked for: a recording is never loaded whole.
//
// For the readers' .cc files only: the MRPT classes are merely declared here, and the public
// headers (recording.h, replay_log.h) do not include this one.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace mrpt::obs {
class CObservation;
class CActionCollection;
}  // namespace mrpt::obs

namespace slamo::platform {

// A rawlog that cannot be read: the message names the file and, once reading began, the record.
class RawlogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One entry of a rawlog: an observation or an action collection (exactly one is set).
struct RawlogEntry {
  std::shared_ptr<const mrpt::obs::CObservation> observation;
  std::shared_ptr<const mrpt::obs::CActionCollection> actions;
};

class RawlogRecords {
 public:
  // Checks `path` in a child process, then opens it (gzip-compressed or not). Throws
  // RawlogError: "<path>: <what the child met>: not a rawlog slamo can read",
  // "<path>: cannot open" or "<path>: cannot open (<MRPT's message>)". Whether the file
  // exists is the caller's to check first (the readers word that error differently).
  // `check_timeout_s` bounds the child's read: longer, and the file is taken as one that hangs
  // MRPT's deserialiser (a 36 MB rawlog reads in about a second).
  explicit RawlogRecords(const std::string& path, double check_timeout_s = 120.0);
  ~RawlogRecords();
  RawlogRecords(const RawlogRecords&) = delete;
  RawlogRecords& operator=(const RawlogRecords&) = delete;

  // The next entry in file order, or nothing at a clean end of the file. A record is an
  // observation, an action collection, a sensory frame (its observations, one entry each) or
  // a nested rawlog (its entries, flattened the same way); the next record is read only when
  // the entries of this one are used up. Throws RawlogError naming the record (1-based) for
  // one that does not deserialise, is cut short by the end of the file, is null or holds a
  // null, or is any other object.
  std::optional<RawlogEntry> Next();

  // "<path>: record <n>: <what>", n the record of the entry Next() gave last: for the
  // caller's own errors about that entry.
  std::string Where(const std::string& what) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slamo::platform
