#include "rmhb/sweep/journal.h"

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace rmhb::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kHeaderKey = "rmhb_sweep_journal";

json SolutionToJson(const FoundSolution& f) {
  const Eigen::MatrixXd& c = f.solution.coefficients();
  json rows = json::array();
  for (int i = 0; i < c.rows(); ++i) rows.push_back(std::vector<double>(c.row(i).begin(), c.row(i).end()));
  return {{"frequencies", f.solution.frequencies()}, {"coefficients", rows}, {"amplitude", f.amplitude},
          {"residual", f.residual}, {"route", f.route}, {"stability", f.stability},
          {"max_real_part", f.max_real_part}};
}

FoundSolution SolutionFromJson(const json& j, const HarmonicBasis& basis, const std::vector<Variable>& variables) {
  const json& rows = j.at("coefficients");
  Eigen::MatrixXd c(static_cast<long>(rows.size()), basis.num_coefficients());
  if (static_cast<int>(rows.size()) != static_cast<int>(variables.size()))
    throw std::invalid_argument("a journaled solution has another number of variables than the model");
  for (int i = 0; i < c.rows(); ++i) {
    const std::vector<double> row = rows[i].get<std::vector<double>>();
    if (static_cast<long>(row.size()) != c.cols())
      throw std::invalid_argument("a journaled solution has another number of coefficients than the basis");
    for (int k = 0; k < c.cols(); ++k) c(i, k) = row[k];
  }
  return FoundSolution{HarmonicSolution(basis, j.at("frequencies").get<std::vector<double>>(), c, variables),
                       j.at("amplitude").get<double>(), j.at("residual").get<double>(),
                       j.at("route").get<std::string>(), j.at("stability").get<std::string>(),
                       j.at("max_real_part").get<double>()};
}

}  // namespace

json PointToJson(const PointResult& p) {
  json solutions = json::array();
  for (const FoundSolution& f : p.solutions) solutions.push_back(SolutionToJson(f));
  return {{"index", p.index}, {"values", p.values}, {"status", ToString(p.status)}, {"message", p.message},
          {"solves", p.solves}, {"non_physical", p.non_physical}, {"seconds", p.seconds},
          {"solutions", solutions}};
}

PointResult PointFromJson(const json& j, const HarmonicBasis& basis, const std::vector<Variable>& variables) {
  PointResult p;
  p.index = j.at("index").get<long>();
  p.values = j.at("values").get<std::vector<double>>();
  p.status = PointStatusFromString(j.at("status").get<std::string>());
  p.message = j.at("message").get<std::string>();
  p.solves = j.at("solves").get<int>();
  p.non_physical = j.at("non_physical").get<int>();
  p.seconds = j.at("seconds").get<double>();
  for (const json& s : j.at("solutions")) p.solutions.push_back(SolutionFromJson(s, basis, variables));
  return p;
}

JournalWriter::JournalWriter(const std::string& directory, int rank, const std::string& fingerprint) {
  std::error_code error;
  fs::create_directories(directory, error);
  const long stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  path_ = (fs::path(directory) / ("rank" + std::to_string(rank) + "-" + std::to_string(::getpid()) + "-" +
                                  std::to_string(stamp) + ".jsonl")).string();
  file_ = std::fopen(path_.c_str(), "wx");
  if (file_ == nullptr) throw std::runtime_error("cannot create the sweep journal " + path_);
  WriteLine(json{{kHeaderKey, 1}, {"fingerprint", fingerprint}}.dump());
}

JournalWriter::~JournalWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void JournalWriter::Append(const json& point) { WriteLine(point.dump()); }

void JournalWriter::WriteLine(const std::string& line) {
  const std::string text = line + "\n";
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0 ||
      ::fsync(::fileno(file_)) != 0)
    throw std::runtime_error("cannot write the sweep journal " + path_);
}

JournalContents ReadJournals(const std::string& directory, const std::string& fingerprint) {
  JournalContents contents;
  std::error_code error;
  if (!fs::is_directory(directory, error)) return contents;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.path().extension() == ".jsonl") files.push_back(entry.path());
  std::sort(files.begin(), files.end());  // a fixed order: "the first copy" is reproducible
  for (const fs::path& path : files) {
    std::ifstream in(path);
    std::string line;
    bool header = true;
    ++contents.files;
    while (std::getline(in, line)) {
      const bool complete = !in.eof();  // the last line of a killed writer has no newline
      const json j = json::parse(line, nullptr, false);
      if (!complete || j.is_discarded() || !j.is_object()) {
        ++contents.torn_lines;
        continue;
      }
      if (header) {
        header = false;
        if (j.value(kHeaderKey, 0) != 1 || j.value("fingerprint", "") != fingerprint)
          throw std::invalid_argument("the journal " + path.string() +
                                      " belongs to another sweep (other model, parameters, grid or "
                                      "options); remove it or use another --out");
        continue;
      }
      const long index = j.at("index").get<long>();
      if (!contents.points.emplace(index, j).second) ++contents.duplicates;
    }
  }
  return contents;
}

}  // namespace rmhb::sweep
