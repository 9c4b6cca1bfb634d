#include "platform/rawlog_reader.h"

#include <cstdint>
#include <deque>
#include <exception>
#include <utility>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include "platform/rawlog_guard.h"

namespace slamo::platform {

struct RawlogRecords::Impl {
  std::string path;
  mrpt::io::CFileGZInputStream file;
  mrpt::serialization::CArchive::UniquePtr archive;
  std::deque<RawlogEntry> pending;  // the rest of the current record's entries
  int record = 0;

  std::string Where(const std::string& what) const {
    return path + ": record " + std::to_string(record) + ": " + what;
  }
  RawlogError Error(const std::string& what) const { return RawlogError(Where(what)); }

  // Reads the next record into `pending`; false at a clean end of the file.
  bool ReadRecord() {
    ++record;
    const uint64_t before = file.getPosition();
    mrpt::serialization::CSerializable::Ptr object;
    try {
      object = archive->ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      if (file.getPosition() == before) return false;  // a clean end between records
      throw Error("truncated (the file ends inside it)");
    } catch (const std::exception& e) {
      throw Error("not a valid MRPT rawlog record (" + MrptErrorGist(e.what()) + ")");
    }
    Add(object);
    return true;
  }

  void Add(const mrpt::serialization::CSerializable::Ptr& object) {
    using namespace mrpt::obs;  // NOLINT(build/namespaces): the MRPT classes, briefly
    if (!object) throw Error("an empty (null) object");
    if (auto observation = std::dynamic_pointer_cast<const CObservation>(object)) {
      pending.push_back({std::move(observation), nullptr});
    } else if (auto actions = std::dynamic_pointer_cast<const CActionCollection>(object)) {
      pending.push_back({nullptr, std::move(actions)});
    } else if (const auto* frame = dynamic_cast<const CSensoryFrame*>(object.get())) {
      for (const auto& o : *frame) Add(o);
    } else if (const auto* rawlog = dynamic_cast<const CRawlog*>(object.get())) {
      for (const auto& entry : *rawlog) Add(entry);
    } else {
      throw Error(std::string("a ") + object->GetRuntimeClass()->className +
                  ", not an observation, sensory frame or action collection: not a rawlog");
    }
  }
};

RawlogRecords::RawlogRecords(const std::string& path, double check_timeout_s)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  // A record that crashes or hangs MRPT's deserialiser does so in a child process.
  if (const std::optional<std::string> crash = CheckRawlogInChildProcess(path, check_timeout_s))
    throw RawlogError(path + ": " + *crash + ": not a rawlog slamo can read");
  bool ok = false;
  try {
    ok = impl_->file.open(path);
  } catch (const std::exception& e) {
    throw RawlogError(path + ": cannot open (" + MrptErrorGist(e.what()) + ")");
  }
  if (!ok) throw RawlogError(path + ": cannot open");
  impl_->archive = mrpt::serialization::archiveUniquePtrFrom(impl_->file);
}

RawlogRecords::~RawlogRecords() = default;

std::optional<RawlogEntry> RawlogRecords::Next() {
  while (impl_->pending.empty()) {
    if (!impl_->ReadRecord()) return std::nullopt;
  }
  RawlogEntry entry = std::move(impl_->pending.front());
  impl_->pending.pop_front();
  return entry;
}

std::string RawlogRecords::Where(const std::string& what) const { return impl_->Where(what); }

}  // namespace slamo::platform
