#include "frequency_id/signal_io.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

namespace rmhb::frequency_id {
namespace {

std::string Trim(const std::string& text) {
  const char* space = " \t\r\n";
  const std::size_t first = text.find_first_not_of(space);
  if (first == std::string::npos) return "";
  const std::size_t last = text.find_last_not_of(space);
  return text.substr(first, last - first + 1);
}

std::vector<std::string> SplitFields(const std::string& line, char delimiter) {
  std::vector<std::string> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = line.find(delimiter, begin);
    fields.push_back(Trim(line.substr(begin, end - begin)));
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return fields;
}

// Locale-independent (unlike strtod), and the whole field must be consumed.
bool ParseNumber(const std::string& field, double* value) {
  if (field.empty()) return false;
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (*first == '+') ++first;  // from_chars does not take a leading '+'
  const auto [end, error] = std::from_chars(first, last, *value);
  return error == std::errc() && end == last && std::isfinite(*value);
}

CsvReadResult Error(CsvStatus status, const std::string& source, int line, int column,
                    const std::string& what) {
  CsvReadResult result;
  result.status = status;
  result.source = source;
  result.line = line;
  result.column = column;
  std::ostringstream os;
  os << source;
  if (line > 0) os << ":" << line;
  if (column > 0) os << ":" << column;
  os << ": " << what;
  result.message = os.str();
  return result;
}

}  // namespace

const char* ToString(CsvStatus status) {
  switch (status) {
    case CsvStatus::kOk: return "OK";
    case CsvStatus::kCannotOpen: return "CANNOT_OPEN";
    case CsvStatus::kEmpty: return "EMPTY";
    case CsvStatus::kNonNumeric: return "NON_NUMERIC";
    case CsvStatus::kRaggedRow: return "RAGGED_ROW";
    case CsvStatus::kTooFewRows: return "TOO_FEW_ROWS";
    case CsvStatus::kNoChannels: return "NO_CHANNELS";
    case CsvStatus::kNonUniformTime: return "NON_UNIFORM_TIME";
  }
  return "UNKNOWN";
}

CsvReadResult ReadSignalCsv(const std::string& path, Signal* signal,
                            const CsvReadOptions& options) {
  std::ifstream file(path);
  if (!file) return Error(CsvStatus::kCannotOpen, path, 0, 0, "cannot open file");
  return ParseSignalCsv(file, path, signal, options);
}

CsvReadResult ParseSignalCsv(std::istream& input, const std::string& source, Signal* signal,
                             const CsvReadOptions& options) {
  std::vector<std::string> names;
  std::vector<double> times;
  std::vector<int> time_lines;  // source line of each row, for messages
  std::vector<double> values;   // row-major
  int width = 0;                // fields per row, fixed by the first row
  int width_line = 0;
  bool first_content = true;
  std::string text;
  for (int line_number = 1; std::getline(input, text); ++line_number) {
    const std::string line = Trim(text);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> fields = SplitFields(line, options.delimiter);
    double value = 0.0;
    if (first_content && !ParseNumber(fields[0], &value)) {
      first_content = false;
      names.assign(fields.begin() + 1, fields.end());
      for (std::string& name : names) {
        if (name.size() >= 2 && name.front() == '"' && name.back() == '"') {
          name = name.substr(1, name.size() - 2);
        }
      }
      width = static_cast<int>(fields.size());
      width_line = line_number;
      continue;
    }
    first_content = false;
    if (width == 0) {
      width = static_cast<int>(fields.size());
      width_line = line_number;
    }
    if (static_cast<int>(fields.size()) != width) {
      std::ostringstream os;
      os << "row has " << fields.size() << " fields, expected " << width << " as on line "
         << width_line;
      return Error(CsvStatus::kRaggedRow, source, line_number,
                   std::min<int>(fields.size(), width) + 1, os.str());
    }
    for (int c = 0; c < width; ++c) {
      if (!ParseNumber(fields[c], &value)) {
        std::ostringstream os;
        if (fields[c].empty()) {
          os << "empty field";
        } else {
          os << "'" << fields[c] << "' is not a finite number";
        }
        if (c == 0) {
          os << " (time column)";
        } else if (c - 1 < static_cast<int>(names.size()) && !names[c - 1].empty()) {
          os << " (channel '" << names[c - 1] << "')";
        }
        return Error(CsvStatus::kNonNumeric, source, line_number, c + 1, os.str());
      }
      if (c == 0) {
        times.push_back(value);
        time_lines.push_back(line_number);
      } else {
        values.push_back(value);
      }
    }
  }
  if (input.bad()) return Error(CsvStatus::kCannotOpen, source, 0, 0, "read error");
  const int rows = static_cast<int>(times.size());
  if (rows == 0) return Error(CsvStatus::kEmpty, source, 0, 0, "no data rows");
  if (width < 2) {
    return Error(CsvStatus::kNoChannels, source, width_line, 0,
                 "only a time column; at least one channel column is needed");
  }
  if (rows < std::max(2, options.min_rows)) {
    std::ostringstream os;
    os << rows << " data rows, at least " << std::max(2, options.min_rows) << " are needed";
    return Error(CsvStatus::kTooFewRows, source, 0, 0, os.str());
  }

  // Order first: a repeated or decreasing time is the more specific error.
  for (int i = 1; i < rows; ++i) {
    if (!(times[i] > times[i - 1])) {
      std::ostringstream os;
      os.precision(10);
      os << "time " << times[i] << " does not increase (previous " << times[i - 1] << ")";
      return Error(CsvStatus::kNonUniformTime, source, time_lines[i], 1, os.str());
    }
  }
  // The mean step is immune to the rounding of individual printed times.
  const double dt = (times.back() - times.front()) / (rows - 1);
  for (int i = 1; i < rows; ++i) {
    const double step = times[i] - times[i - 1];
    if (std::abs(step - dt) > options.time_tolerance * dt) {
      std::ostringstream os;
      os.precision(10);
      os << "non-uniform sampling: step " << step << " from the previous row, mean step " << dt
         << " (relative difference " << std::abs(step - dt) / dt << " > time_tolerance "
         << options.time_tolerance << ")";
      return Error(CsvStatus::kNonUniformTime, source, time_lines[i], 1, os.str());
    }
  }

  const int channels = width - 1;
  Signal result;
  result.dt = dt;
  result.t0 = times.front();
  result.samples.resize(rows, channels);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < channels; ++c) result.samples(r, c) = values[r * channels + c];
  }
  if (!names.empty()) {
    result.channel_names = names;
    for (int c = 0; c < channels; ++c) {
      if (result.channel_names[c].empty()) result.channel_names[c] = "x" + std::to_string(c + 1);
    }
  }
  *signal = std::move(result);
  CsvReadResult ok;
  ok.source = source;
  return ok;
}

}  // namespace rmhb::frequency_id
