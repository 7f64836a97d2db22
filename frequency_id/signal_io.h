#ifndef RMHB_FREQUENCY_ID_SIGNAL_IO_H_
#define RMHB_FREQUENCY_ID_SIGNAL_IO_H_

#include <istream>
#include <string>

#include "frequency_id/signal.h"

namespace rmhb::frequency_id {

// CSV layout: the first column is time, every further column one channel.
// The first non-comment line is a header of names when its first field is
// not a number. Blank lines and lines starting with '#' are skipped. Fields
// may be padded with spaces; CRLF line ends are accepted.
struct CsvReadOptions {
  char delimiter = ',';
  // Sampling must be uniform: every step may differ from the mean step
  // (t_last - t_first) / (rows - 1) by at most this fraction of it. Loosen it
  // for times printed with few digits.
  double time_tolerance = 1e-6;
  // Fewer data rows than this is an error.
  int min_rows = 4;
};

enum class CsvStatus {
  kOk,
  kCannotOpen,
  kEmpty,          // no data rows at all
  kNonNumeric,     // a field that is not a finite number (or is empty)
  kRaggedRow,      // a row whose field count differs from the first row's
  kTooFewRows,
  kNoChannels,     // only a time column
  kNonUniformTime, // decreasing, repeated, or unevenly spaced times
};
const char* ToString(CsvStatus status);

// Where and why reading failed. line and column are 1-based (column counts
// fields, not characters) and 0 when they do not apply; message repeats them
// as "source:line:column: ...".
struct CsvReadResult {
  CsvStatus status = CsvStatus::kOk;
  std::string message;
  std::string source;
  int line = 0;
  int column = 0;

  bool ok() const { return status == CsvStatus::kOk; }
};

// Reads a signal from a CSV file. On failure `signal` is left untouched and
// the result says what is wrong; nothing is thrown for bad content.
CsvReadResult ReadSignalCsv(const std::string& path, Signal* signal,
                            const CsvReadOptions& options = CsvReadOptions());

// The same from a stream; `source` names it in messages.
CsvReadResult ParseSignalCsv(std::istream& input, const std::string& source, Signal* signal,
                             const CsvReadOptions& options = CsvReadOptions());

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_SIGNAL_IO_H_
