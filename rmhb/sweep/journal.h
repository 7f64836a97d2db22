#ifndef RMHB_SWEEP_JOURNAL_H_
#define RMHB_SWEEP_JOURNAL_H_

// The sweep's checkpoint: every finished point, appended as one JSON line to
// a file of the process that computed it, flushed and fsync'ed before the
// next point starts. A process killed at any moment loses at most the point
// it was computing; a line cut off by the kill is not valid JSON (or has no
// newline) and is skipped on reading. Each file starts with a header line
// holding the sweep's fingerprint (model, parameters, grid, options), so a
// journal of another sweep is refused rather than mixed in.
//
// Numbers are written so that they read back to the same double (nlohmann's
// shortest round-trip form): a point continued from a journaled point after
// a resume starts from exactly the bits it would have had in memory.

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rmhb/sweep/sweep.h"

namespace rmhb::sweep {

nlohmann::json PointToJson(const PointResult& point);
// `basis` and `variables`: the sweep's (the same at every point).
PointResult PointFromJson(const nlohmann::json& json, const HarmonicBasis& basis,
                          const std::vector<Variable>& variables);

class JournalWriter {
 public:
  // Creates `directory` if needed and a new file in it, unique to this
  // process. Throws std::runtime_error naming the path when it cannot.
  JournalWriter(const std::string& directory, int rank, const std::string& fingerprint);
  ~JournalWriter();
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;

  // One line, on disk when this returns. Throws std::runtime_error on an I/O error.
  void Append(const nlohmann::json& point);
  const std::string& path() const { return path_; }

 private:
  void WriteLine(const std::string& line);
  std::string path_;
  std::FILE* file_ = nullptr;
};

struct JournalContents {
  std::map<long, nlohmann::json> points;  // by point index; the first copy read
  long duplicates = 0;   // points found more than once (a point computed twice)
  long torn_lines = 0;   // cut off by a kill, skipped
  int files = 0;
};

// Every journal file in `directory` (none if it does not exist). Throws
// std::invalid_argument when a file belongs to a sweep with another fingerprint.
JournalContents ReadJournals(const std::string& directory, const std::string& fingerprint);

}  // namespace rmhb::sweep

#endif  // RMHB_SWEEP_JOURNAL_H_
