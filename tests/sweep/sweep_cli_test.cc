// `rmhb sweep` end to end, as a user runs it: the HDF5 file, the JSON, the
// exit codes of bad input, a SIGKILL part-way and --resume, and MPI ranks.

#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

namespace {

namespace fs = std::filesystem;

struct ShellRun {
  int code;
  std::string out;
};

ShellRun Shell(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

const std::string kModel = "tests/sweep/models/hardening.yaml";
const std::string kGrid = " --grid W=1.2:2.0:12 --grid P=0.2:0.3:3 --order 12 --starts 4";

std::string Sweep(const std::string& args) { return std::string(RMHB_CLI) + " sweep " + kModel + args; }

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("rmhb-sweep-cli-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<hsize_t> Dims(hid_t file, const char* name) {
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(set, 0) << name;
  const hid_t space = H5Dget_space(set);
  std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(space));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(set);
  return dims;
}

std::string RootAttribute(hid_t file, const char* name) {
  const hid_t attribute = H5Aopen(file, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attribute);
  char* text = nullptr;
  H5Aread(attribute, type, &text);
  std::string value = text ? text : "";
  H5free_memory(text);
  H5Tclose(type);
  H5Aclose(attribute);
  return value;
}

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// "point 12 rank 1 ..." -> every point index computed, with repeats.
std::multiset<long> ComputedPoints(const std::string& log) {
  std::multiset<long> points;
  for (const std::string& line : Lines(log)) points.insert(std::stol(line.substr(6)));
  return points;
}

TEST(SweepCli, WritesTheFileTheJsonAndTheMap) {
  const TempDir dir;
  const ShellRun run = Shell(Sweep(kGrid + " --json --out " + (dir / "a.h5") + " --plot " + (dir / "map.png")));
  ASSERT_EQ(run.code, 0) << run.out;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["points"], 36);
  EXPECT_EQ(j["computed"], 36);
  EXPECT_EQ(j["duplicates"], 0);
  EXPECT_EQ(j["failed"], 0);
  EXPECT_GT(j["solutions"].get<long>(), 36);  // the bistable band
  EXPECT_GT(j["points_per_second"].get<double>(), 0);
  EXPECT_GT(j["peak_memory_mib_per_rank"].get<double>(), 0);
  EXPECT_FALSE(fs::exists(dir / "a.h5.journal"));
  EXPECT_GT(fs::file_size(dir / "map.png"), 1000u);

  const hid_t file = H5Fopen((dir / "a.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(Dims(file, "/points/status"), (std::vector<hsize_t>{36}));
  EXPECT_EQ(Dims(file, "/points/values"), (std::vector<hsize_t>{36, 2}));
  EXPECT_EQ(Dims(file, "/map/count"), (std::vector<hsize_t>{3, 12}));
  EXPECT_EQ(Dims(file, "/grid/W"), (std::vector<hsize_t>{12}));
  const std::vector<hsize_t> c = Dims(file, "/solutions/coefficients");
  EXPECT_EQ(c[0], j["solutions"].get<hsize_t>());
  EXPECT_EQ(c[2], 25u);  // 2 N + 1
  EXPECT_EQ(RootAttribute(file, "model_text"), Bytes(kModel));
  EXPECT_EQ(RootAttribute(file, "software").rfind("rmhb ", 0), 0u);
  EXPECT_NE(RootAttribute(file, "options").find("\"starts\":4"), std::string::npos);
  H5Fclose(file);
}

TEST(SweepCli, BadInputIsExitTwoWithTheReason) {
  const TempDir dir;
  const std::string out = " --out " + (dir / "b.h5");
  struct Case {
    std::string args, says;
  } cases[] = {
      {" --grid W=1:2", "NAME=a:b:n"},
      {" --grid Q=1:2:3", "Q"},
      {" --grid W=1:2:3 --tol 1e-10", "--tol"},
      {" --grid W=1:2:3 --plot map.jpg", ".png or .svg"},
      {" --grid W=1:2:3 --grid P=1:2:2 --grid zeta=0.1:0.2:2 --plot map.png", "one or two axes"},
      {" --grid W=1:2:3 --range 2:1", "--range"},
  };
  for (const Case& c : cases) {
    const ShellRun run = Shell(Sweep(c.args + out) + " 2>&1");
    EXPECT_EQ(run.code, 2) << c.args << "\n" << run.out;
    EXPECT_NE(run.out.find(c.says), std::string::npos) << c.args << "\n" << run.out;
  }
  fs::create_directories(dir / "b.h5.journal");
  const ShellRun exists = Shell(Sweep(" --grid W=1:2:3" + out) + " 2>&1");
  EXPECT_EQ(exists.code, 2);
  EXPECT_NE(exists.out.find("--resume"), std::string::npos) << exists.out;
  // A journal of another sweep is refused, not mixed in.
  ASSERT_EQ(Shell(Sweep(" --grid W=1:2:3 --starts 1 --keep-journal" + out + " --resume")).code, 0);
  const ShellRun other = Shell(Sweep(" --grid W=1:2:3 --starts 2" + out + " --resume") + " 2>&1");
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.out.find("another sweep"), std::string::npos) << other.out;
}

// Waits until `log` has at least `lines` lines (or the process ended).
void WaitForLines(const std::string& log, std::size_t lines, pid_t pid) {
  for (int i = 0; i < 2000 && Lines(log).size() < lines; ++i) {
    if (waitpid(pid, nullptr, WNOHANG) == pid) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

pid_t Start(const std::string& command) {
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + command + " > /dev/null 2>&1").c_str(), nullptr);
    _exit(127);
  }
  return pid;
}

TEST(SweepCli, KilledPartWayAndResumedGivesTheSameFileAndNoPointTwice) {
  const TempDir dir;
  ASSERT_EQ(Shell(Sweep(kGrid + " --out " + (dir / "whole.h5"))).code, 0);
  const std::string args = kGrid + " --out " + (dir / "cut.h5") + " --log " + (dir / "cut.log");
  const pid_t pid = Start(Sweep(args));
  WaitForLines(dir / "cut.log", 14, pid);
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  const std::size_t before = Lines(dir / "cut.log").size();
  ASSERT_LT(before, 36u) << "the sweep finished before it was killed";
  ASSERT_TRUE(fs::exists(dir / "cut.h5.journal"));
  const ShellRun resumed = Shell(Sweep(args + " --resume --json"));
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  const nlohmann::json j = nlohmann::json::parse(resumed.out);
  EXPECT_EQ(j["computed"].get<long>() + j["resumed"].get<long>(), 36);
  EXPECT_EQ(j["duplicates"], 0);
  EXPECT_EQ(Bytes(dir / "cut.h5"), Bytes(dir / "whole.h5"));
  // The log line follows the journal's fsync: the kill may land between
  // them, leaving the log one line short, never a point computed twice.
  const std::multiset<long> computed = ComputedPoints(dir / "cut.log");
  EXPECT_EQ(std::set<long>(computed.begin(), computed.end()).size(), computed.size()) << "a point computed twice";
  EXPECT_GE(computed.size(), 35u);
}

// Ranks oversubscribed (this machine may have fewer cores), allowed as root
// (CI containers). Under the sanitizers OpenMPI's own start-up allocations,
// made in components it dlopens and unloads at MPI_Finalize, would read as
// leaks from an "unknown module" that no suppression can name: leak
// detection is off for MPI ranks only (every single-process run keeps it).
std::string MpiRun(int ranks) {
  return std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
                     "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 ") +
         MPIRUN + " -n " + std::to_string(ranks) + " ";
}

TEST(SweepCli, OneTwoAndThreeRanksWriteTheSameBytesAndARankKilledResumes) {
  const TempDir dir;
  ASSERT_EQ(Shell(Sweep(kGrid + " --out " + (dir / "one.h5"))).code, 0);
  for (int ranks : {2, 3}) {
    const std::string out = dir / ("r" + std::to_string(ranks) + ".h5");
    const ShellRun run = Shell(MpiRun(ranks) + Sweep(kGrid + " --json --out " + out));
    ASSERT_EQ(run.code, 0) << run.out;
    EXPECT_EQ(nlohmann::json::parse(run.out)["computing_ranks"], ranks - 1);
    EXPECT_EQ(Bytes(out), Bytes(dir / "one.h5")) << ranks << " ranks";
  }
  // SIGKILL one rank part-way: mpirun ends the job; --resume on 2 ranks.
  const std::string args = kGrid + " --out " + (dir / "k.h5") + " --log " + (dir / "k.log");
  const pid_t job = Start(MpiRun(3) + Sweep(args));
  WaitForLines(dir / "k.log", 12, job);
  Shell("pkill -KILL -n -f 'rmhb sweep .*" + (dir / "k.h5") + "'");
  waitpid(job, nullptr, 0);
  ASSERT_LT(Lines(dir / "k.log").size(), 36u) << "the sweep finished before a rank was killed";
  const ShellRun resumed = Shell(MpiRun(2) + Sweep(args + " --resume"));
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_EQ(Bytes(dir / "k.h5"), Bytes(dir / "one.h5"));
  const std::multiset<long> computed = ComputedPoints(dir / "k.log");
  EXPECT_EQ(std::set<long>(computed.begin(), computed.end()).size(), computed.size()) << "a point computed twice";
  EXPECT_GE(computed.size(), 34u);  // a line short per computing rank the kill caught between journal and log
}

}  // namespace

namespace {

// Without what depends on the machine and the number of processes.
nlohmann::json Census(const std::string& command) {
  const ShellRun run = Shell(command);
  EXPECT_EQ(run.code, 0) << run.out;
  nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* key : {"seconds", "threads", "ranks"}) j.erase(key);
  for (nlohmann::json& m : j["methods"]) m.erase("solve_cpu_seconds");
  return j;
}

TEST(MonteCarloMpi, ThreeRanksTakeTheSameCensusAsOne) {
  const std::string args = " montecarlo " + kModel + " --starts 600 --order 3 --threads 1 --json";
  const nlohmann::json one = Census(std::string(RMHB_CLI) + args);
  EXPECT_EQ(Census(MpiRun(3) + RMHB_CLI + args), one);
  EXPECT_GT(one["methods"][1]["distinct_solutions"].get<int>(), 1);
}

}  // namespace
