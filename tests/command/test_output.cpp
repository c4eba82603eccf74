// End-to-end tests of ffsr-optimize's output files as people use them from a shell
// (src/cli/support/output.hpp, Outputs): '-' is standard output (the table then goes to standard error),
// FIFOs and devices are written directly and never replaced, a symbolic link is followed and its
// target replaced atomically, and every write error -- a full disk, a reader that closed the pipe --
// is one error line naming the output, exit 2 and no partial regular file.
#include "support/command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

// Then the regression runs (--expect BASELINE.json, --rtol, --atol): a result compared with itself
// passes, a moved, missing or extra value gives exit 4 and one line per difference, a bad baseline
// gives exit 2 naming the file.
//
// Every child process runs with a timeout (tests/support/run_command.hpp, or the helpers below), so
// a FIFO nobody reads or a blocked pipe fails a test instead of hanging the suite.

namespace test_output {

namespace fs = std::filesystem;
using namespace ffsr::test;
using nlohmann::json;

namespace {

/// The command in `cwd`; the main job without the global search: these tests are about the output
/// files, and the search costs minutes at -O0 with ASan (its own tests are in test_global)
CommandResult cli(const Args& args, const std::string& cwd) {
  Args full;
  const bool main_job = args.empty() || (args[0] != "inspect" && args[0] != "contact" && args[0] != "map" &&
                                         args[0] != "robust" && args[0] != "xi");
  if (main_job) full.insert(full.end(), {"--global", "false"});
  full.insert(full.end(), args.begin(), args.end());
  return ffsr::test::cli(full, cwd, 60.0);
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// One error line with the prefix, naming every string of `names`.
void check_one_error_line(const CommandResult& r, const std::vector<std::string>& names) {
  INFO("exit " << r.exit_code << "\nstdout: [" << r.out.substr(0, 300) << "]\nstderr: [" << r.err << "]");
  CHECK_FALSE(r.signaled);
  CHECK(r.err.rfind(kErrorPrefix, 0) == 0);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  for (const auto& n : names) {
    INFO("the error must name: " << n);
    CHECK(contains(r.err, n));
  }
}

/// The main job's JSON result: the two runs and the reductions.
void check_result(const json& j) {
  REQUIRE(j.is_object());
  for (const char* key : {"baseline", "optimized", "mass_reduction_percent", "scenario", "version"})
    CHECK(j.contains(key));
  const double m0 = j.at("baseline").at("integrated_effective_mass").get<double>();
  const double m1 = j.at("optimized").at("integrated_effective_mass").get<double>();
  // identity: the reduction printed is the one of the two masses printed
  CHECK(j.at("mass_reduction_percent").get<double>() == Approx(100.0 * (m0 - m1) / m0).epsilon(1e-12));
}

bool is_char_device(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

/// Runs the command with standard output on a pipe whose reading end is already closed: every
/// write to standard output fails with EPIPE (or kills the process if SIGPIPE is not handled).
CommandResult run_with_closed_stdout(const Args& args, double timeout_s = 60.0) {
  Args full{kCli};
  full.insert(full.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : full) argv.push_back(a.data());
  argv.push_back(nullptr);
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  ::close(fds[0]);  // the reader is gone before the first byte
  const int err_fd = ffsr::test::detail::anonymous_file();
  TempDir cwd;
  const std::string dir = cwd.str();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::signal(SIGPIPE, SIG_DFL);  // as a shell starts it: the command must handle SIGPIPE itself
    const int in_fd = ::open("/dev/null", O_RDONLY);
    if (in_fd >= 0) ::dup2(in_fd, 0);
    ::dup2(fds[1], 1);
    ::dup2(err_fd, 2);
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  CommandResult r = ffsr::test::detail::wait_for(pid, timeout_s);
  r.err = ffsr::test::detail::read_all(err_fd);
  ::close(err_fd);
  return r;
}

/// Reads a FIFO in a thread, as another program would, until the writer is done; bounded by a
/// deadline so that a command that never writes cannot hang the test.
class FifoReader {
 public:
  explicit FifoReader(const std::string& path) {
    // O_NONBLOCK: the open does not wait for a writer, so the thread can always be stopped
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK);
    if (fd_ >= 0) thread_ = std::thread([this] { run(); });
  }
  ~FifoReader() {
    writer_done_ = true;
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) ::close(fd_);
  }
  bool opened() const { return fd_ >= 0; }
  /// Call once the command has exited: reads what is left and returns everything read.
  std::string finish() {
    writer_done_ = true;
    if (thread_.joinable()) thread_.join();
    return data_;
  }

 private:
  void run() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    char buf[65536];
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd_, POLLIN, 0};
      ::poll(&p, 1, 20);
      const ssize_t k = ::read(fd_, buf, sizeof buf);
      if (k > 0) {
        data_.append(buf, static_cast<size_t>(k));
        continue;
      }
      // k == 0: no writer (not yet, or not any more); k < 0: EAGAIN while a writer is open
      if (k == 0 && writer_done_) break;
      if (k == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  int fd_ = -1;
  std::thread thread_;
  std::atomic<bool> writer_done_{false};
  std::string data_;
};

}  // namespace

// ------------------------------------------------------------------------------------------------
// 1. '-' is standard output
// ------------------------------------------------------------------------------------------------

TEST_CASE("output: --json - prints the result on standard output, the table on standard error", "[output]") {
  TempDir tmp;
  // without --quiet: with it nothing but an error reaches standard error (the table neither)
  const auto r = cli({"--json", "-"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  json j;
  REQUIRE_NOTHROW(j = json::parse(r.out));  // what `ffsr-optimize --json - | jq .` reads
  check_result(j);
  CHECK(contains(r.err, "Without optimization"));
  CHECK(contains(r.err, "With optimization"));
  CHECK_FALSE(contains(r.out, "Without optimization"));
  CHECK(tmp.entries().empty());  // no file named '-'

  SECTION("the same result as --json FILE") {
    REQUIRE(cli({"--quiet", "--json", "out.json"}, tmp.str()).exit_code == 0);
    const json f = json::parse(read_file(tmp / "out.json"));
    CHECK(f.at("baseline") == j.at("baseline"));
    CHECK(f.at("optimized") == j.at("optimized"));
  }
  SECTION("--csv - with --json FILE: the series on standard output, the JSON in its file") {
    const auto c = cli({"--csv", "-", "--json", "out.json"}, tmp.str());
    REQUIRE(c.exit_code == 0);
    CHECK(c.out.rfind("run,t,", 0) == 0);
    CHECK(contains(c.out, "\noptimized,"));
    CHECK(contains(c.err, "With optimization"));
    CHECK(tmp.entries() == std::vector<std::string>{"out.json"});
  }
  SECTION("contact --series - prints the CSV, the table goes to standard error") {
    const auto c = cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--series", "-"}, tmp.str());
    INFO(c.err);
    REQUIRE(c.exit_code == 0);
    CHECK(c.out.rfind("model,t_s,force_N,delta_m\n", 0) == 0);
    CHECK(contains(c.err, "integrated effective mass"));
    CHECK(tmp.entries().empty());
  }
}

TEST_CASE("at most one output may be standard output: an error naming both flags", "[output]") {
  TempDir tmp;
  struct Case {
    Args args;
    std::vector<std::string> names;
  };
  const std::vector<Case> cases{
      {{"--quiet", "--json", "-", "--csv", "-"}, {"--json -", "--csv -", "standard output"}},
      {{"--quiet", "--json", "/dev/stdout", "--csv", "-"}, {"--json /dev/stdout", "--csv -"}},
      {{"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--json", "--series", "-"},
       {"--json", "--series -"}},
  };
  for (const auto& c : cases) {
    const auto r = cli(c.args, tmp.str());
    CHECK(r.exit_code == 2);
    check_one_error_line(r, c.names);
    CHECK(r.out.empty());
    CHECK(tmp.entries().empty());
  }
}

// ------------------------------------------------------------------------------------------------
// 2. FIFOs, devices and symbolic links
// ------------------------------------------------------------------------------------------------

TEST_CASE("a FIFO read by another thread receives the JSON and stays a FIFO", "[output]") {
  TempDir tmp;
  const std::string fifo = tmp / "result.fifo";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  FifoReader reader(fifo);
  REQUIRE(reader.opened());
  const auto r = cli({"--quiet", "--json", fifo, "--csv", "series.csv"}, tmp.str());
  const std::string got = reader.finish();
  INFO(r.err);
  REQUIRE_FALSE(r.timed_out);
  REQUIRE(r.exit_code == 0);
  json j;
  REQUIRE_NOTHROW(j = json::parse(got));
  check_result(j);
  struct stat st {};
  REQUIRE(::lstat(fifo.c_str(), &st) == 0);
  CHECK(S_ISFIFO(st.st_mode));                                                    // not renamed over
  CHECK(tmp.entries() == std::vector<std::string>{"result.fifo", "series.csv"});  // no temporary file left
}

TEST_CASE("devices: /dev/null is written, not replaced, and /dev/full is a write error naming it",
          "[output]") {
  TempDir tmp;
  REQUIRE(is_char_device("/dev/null"));
  const auto r = cli({"--quiet", "--json", "/dev/null", "--csv", "/dev/null"}, tmp.str());
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(is_char_device("/dev/null"));
  CHECK(tmp.entries().empty());
  if (is_char_device("/dev/full")) {  // Linux: every write fails with ENOSPC
    const auto f = cli({"--quiet", "--json", "/dev/full", "--csv", "out.csv"}, tmp.str());
    CHECK(f.exit_code == 2);
    check_one_error_line(f, {"/dev/full", "--json", "No space left on device"});
    CHECK(is_char_device("/dev/full"));
    CHECK(tmp.entries().empty());  // out.csv was not renamed into place
  }
}

TEST_CASE("a symbolic link is followed: the target is replaced, the link stays a link", "[output]") {
  TempDir tmp;
  fs::create_directory(tmp.path() / "data");
  write_text(tmp / "data/result.json", "{\"earlier\": true}\n");
  fs::create_symlink("data/result.json", tmp.path() / "latest.json");      // relative to the link's folder
  fs::create_symlink(tmp / "data/series.csv", tmp.path() / "series.csv");  // dangling: names a new file
  const auto r = cli({"--quiet", "--json", "latest.json", "--csv", "series.csv"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::is_symlink(tmp.path() / "latest.json"));
  CHECK(fs::read_symlink(tmp.path() / "latest.json") == fs::path("data/result.json"));
  CHECK(fs::is_symlink(tmp.path() / "series.csv"));
  const json j = json::parse(read_file(tmp / "data/result.json"));
  check_result(j);
  CHECK(read_file(tmp / "data/series.csv").rfind("run,t,", 0) == 0);
  // the temporary files were made next to the targets and renamed: nothing else is left
  CHECK(tmp.entries() == std::vector<std::string>{"data", "latest.json", "series.csv"});
  std::vector<std::string> in_data;
  for (const auto& e : fs::directory_iterator(tmp.path() / "data"))
    in_data.push_back(e.path().filename().string());
  std::sort(in_data.begin(), in_data.end());
  CHECK(in_data == std::vector<std::string>{"result.json", "series.csv"});
}

// ------------------------------------------------------------------------------------------------
// 3. write errors: a full disk, a closed pipe
// ------------------------------------------------------------------------------------------------

TEST_CASE("a full disk: exit 2 naming the file, no output file left (tmpfs of 64 KiB, root only)",
          "[output]") {
  if (::geteuid() != 0) {
    WARN("skipped: mounting a small tmpfs needs root (the full-disk case is covered by /dev/full)");
    return;
  }
  TempDir tmp;
  const std::string mnt = tmp / "small";
  fs::create_directory(mnt);
  if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=64k") != 0) {
    WARN("skipped: cannot mount a tmpfs here (" << std::strerror(errno) << ")");
    return;
  }
  struct Unmount {
    std::string path;
    ~Unmount() { ::umount2(path.c_str(), MNT_DETACH); }
  } unmount{mnt};
  // the series CSV of the built-in scenario is ~680 kB, the JSON ~4 kB: the CSV cannot fit
  const auto r = cli({"--quiet", "--json", mnt + "/out.json", "--csv", mnt + "/out.csv"}, tmp.str());
  CHECK(r.exit_code == 2);
  check_one_error_line(r, {mnt + "/out.csv", "--csv", "No space left on device"});
  CHECK(r.out.empty());
  CHECK(fs::is_empty(mnt));  // neither out.json nor a temporary file

  // an earlier result survives a failing run
  write_text(mnt + "/out.csv", "earlier\n");
  const auto again = cli({"--quiet", "--csv", mnt + "/out.csv"}, tmp.str());
  CHECK(again.exit_code == 2);
  CHECK(read_file(mnt + "/out.csv") == "earlier\n");
}

TEST_CASE("a reader that closed the pipe: exit 2 with one line, not a crash", "[output]") {
  SECTION("--json - (the JSON itself)") {
    const auto r = run_with_closed_stdout({"--quiet", "--global", "false", "--json", "-"});
    REQUIRE_FALSE(r.timed_out);
    CHECK(r.exit_code == 2);
    check_one_error_line(r, {"standard output", "--json -", "Broken pipe"});
  }
  SECTION("the table on standard output") {
    const auto r = run_with_closed_stdout({"--quiet", "--global", "false"});
    REQUIRE_FALSE(r.timed_out);
    CHECK(r.exit_code == 2);
    check_one_error_line(r, {"standard output", "cannot write"});
  }
  SECTION("inspect --json") {
    const auto r =
        run_with_closed_stdout({"inspect", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--json"});
    REQUIRE_FALSE(r.timed_out);
    CHECK(r.exit_code == 2);
    check_one_error_line(r, {"standard output"});
  }
}

// ------------------------------------------------------------------------------------------------
// 4. one transaction: the figures, the JSON and the CSV appear together or not at all
// ------------------------------------------------------------------------------------------------

namespace {

/// The built-in 3-DOF scenario with an [uncertainty] table (robust's input), written into `dir`.
std::string uncertain_scenario(const TempDir& dir) {
  std::string toml = read_file(kSource + "/robots/paper_3dof.toml");
  const std::string from = "urdf = \"paper_3dof.urdf\"";
  const size_t at = toml.find(from);
  REQUIRE(at != std::string::npos);
  toml.replace(at, from.size(), "urdf = \"" + kUrdf3 + "\"");
  const std::string path = dir / "uncertain.toml";
  write_text(path, toml + "\n[uncertainty]\nsamples = 4\nseed = 3\n"
                          "target-mass = { law = \"uniform\", relative = 0.1 }\n");
  return path;
}

/// Every subcommand that draws (--plot), with a small run of it on the built-in 3-DOF scenario.
std::vector<std::pair<std::string, Args>> drawing_runs(const TempDir& inputs) {
  return {{"main job", {"--global", "false"}},
          {"detumble", {"detumble", "--joint-torque-limit", "20"}},
          {"xi", {"xi", "--points", "3"}},
          {"contact", {"contact"}},
          {"map", {"map", "--vary", "1", "--step-deg", "90"}},
          {"robust", {"robust", "--config", uncertain_scenario(inputs), "--global", "false"}},
          {"pareto", {"pareto", "--levels", "2", "--starts", "2", "--global-starts", "2"}},
          {"closed-loop", {"closed-loop", "--control-rate", "5", "--estimate-rate", "1"}}};
}

Args with(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

}  // namespace

TEST_CASE("a JSON that cannot be written leaves no figure of --plot behind, in every subcommand",
          "[output][transaction]") {
  TempDir inputs;
  for (const auto& [name, run] : drawing_runs(inputs)) {
    // a missing folder for the JSON, then a full disk (/dev/full: every write fails)
    std::vector<std::pair<std::string, std::string>> failures{{"/nonexistent-ffsr-dir/x.json", "x.json"}};
    if (is_char_device("/dev/full")) failures.emplace_back("/dev/full", "No space left on device");
    for (const auto& [json_path, says] : failures) {
      TempDir tmp;
      fs::create_directory(tmp.path() / "figures");
      const auto r =
          ffsr::test::cli(with(run, {"--quiet", "--plot", "figures", "--json", json_path}), tmp.str());
      INFO(name << " --json " << json_path);
      CHECK(r.exit_code == 2);
      check_one_error_line(r, {json_path, "--json", says});
      CHECK(r.out.empty());
      CHECK(tmp.entries() == std::vector<std::string>{"figures"});
      CHECK(fs::is_empty(tmp.path() / "figures"));  // no figure, no scratch folder
    }
  }
}

TEST_CASE("the figures appear with the JSON when every output is written", "[output][transaction]") {
  // the control of the case above: the same runs draw when the JSON can be written
  for (const Args& run : {Args{"--global", "false"}, Args{"detumble", "--joint-torque-limit", "20"}}) {
    TempDir tmp;
    fs::create_directory(tmp.path() / "figures");
    const auto r =
        ffsr::test::cli(with(run, {"--quiet", "--plot", "figures", "--json", "r.json"}), tmp.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(tmp.entries() == std::vector<std::string>{"figures", "r.json"});
    std::vector<std::string> drawn;
    for (const auto& e : fs::directory_iterator(tmp.path() / "figures"))
      drawn.push_back(e.path().filename().string());
    CHECK_FALSE(drawn.empty());
    for (const auto& f : drawn) CHECK((f.size() > 4 && f.substr(f.size() - 4) == ".png"));  // no scratch left
  }
}

TEST_CASE("map: a JSON that cannot be written leaves neither the streamed CSV nor a figure",
          "[output][transaction]") {
  TempDir tmp;
  fs::create_directory(tmp.path() / "figures");
  write_text(tmp / "map.csv", "earlier\n");
  const auto r = ffsr::test::cli({"map", "--vary", "1", "--step-deg", "90", "--quiet", "--csv", "map.csv",
                                  "--plot", "figures", "--json", "/nonexistent-ffsr-dir/m.json"},
                                 tmp.str());
  CHECK(r.exit_code == 2);
  check_one_error_line(r, {"/nonexistent-ffsr-dir/m.json", "--json"});
  CHECK(tmp.entries() == std::vector<std::string>{"figures", "map.csv"});  // no temporary file
  CHECK(read_file(tmp / "map.csv") == "earlier\n");                        // the earlier map stays
  CHECK(fs::is_empty(tmp.path() / "figures"));
}

TEST_CASE("two outputs to one file: an error naming both flags, nothing written", "[output][transaction]") {
  TempDir tmp;
  write_text(tmp / "r.json", "earlier\n");
  fs::create_symlink("r.json", tmp.path() / "link.json");
  fs::create_directory(tmp.path() / "sub");
  struct Case {
    Args args;
    std::vector<std::string> names;
  };
  const std::vector<Case> cases{
      {{"--global", "false", "--json", "r.json", "--csv", "r.json"}, {"--json r.json", "--csv r.json"}},
      {{"--global", "false", "--json", "./r.json", "--csv", "r.json"}, {"--json ./r.json", "--csv r.json"}},
      {{"--global", "false", "--json", "sub/../r.json", "--csv", tmp / "r.json"},
       {"--json sub/../r.json", "--csv " + (tmp / "r.json")}},
      {{"--global", "false", "--json", "link.json", "--csv", "r.json"}, {"--json link.json", "--csv r.json"}},
      {{"contact", "--json", "r.json", "--series", "./r.json"}, {"--json r.json", "--series ./r.json"}},
      {{"map", "--vary", "1", "--step-deg", "90", "--json", "r.json", "--csv", "./r.json"},
       {"--json r.json", "--csv ./r.json"}},
  };
  for (const auto& c : cases) {
    const auto r = ffsr::test::cli(with(c.args, {"--quiet"}), tmp.str());
    INFO(r.err);
    CHECK(r.exit_code == 2);
    check_one_error_line(r, with(c.names, {"two outputs to one file"}));
    CHECK(r.out.empty());
    CHECK(tmp.entries() == std::vector<std::string>{"link.json", "r.json", "sub"});
    CHECK(read_file(tmp / "r.json") == "earlier\n");
  }
  // a figure's file named by another output: refused before anything is written
  const Args drawn_over{"detumble", "--joint-torque-limit", "20", "--quiet",
                        "--plot",   ".",                    "--json", "detumble.png"};
  const auto f = ffsr::test::cli(drawn_over, tmp.str());
  CHECK(f.exit_code == 2);
  check_one_error_line(f, {"--plot .", "detumble.png", "--json", "two outputs to one file"});
  CHECK(tmp.entries() == std::vector<std::string>{"link.json", "r.json", "sub"});
}

// ------------------------------------------------------------------------------------------------
// 5. regression runs: --expect BASELINE.json
// ------------------------------------------------------------------------------------------------

namespace {

/// The lines of stderr that report a moved value (all but the final error line).
std::vector<std::string> moved_lines(const std::string& err) {
  std::vector<std::string> lines;
  std::stringstream ss(err);
  std::string line;
  while (std::getline(ss, line))
    if (line.rfind(kErrorPrefix, 0) != 0) lines.push_back(line);
  return lines;
}

}  // namespace

TEST_CASE("expect: a result compared with itself passes, a moved value gives exit 4 naming it",
          "[output][expect]") {
  TempDir tmp;
  REQUIRE(cli({"--quiet", "--json", "base.json"}, tmp.str()).exit_code == 0);
  const json base = json::parse(read_file(tmp / "base.json"));

  const auto same = cli({"--quiet", "--expect", "base.json"}, tmp.str());
  INFO(same.err);
  CHECK(same.exit_code == 0);
  CHECK(same.err.empty());

  auto expect_with = [&](const json& stored, Args extra = {}) {
    write_text(tmp / "stored.json", stored.dump(2));
    Args args{"--quiet", "--expect", "stored.json"};
    args.insert(args.end(), extra.begin(), extra.end());
    return cli(args, tmp.str());
  };
  const double m = base.at("optimized").at("integrated_effective_mass").get<double>();

  {  // one value moved by 0.1 %
    json moved = base;
    moved["optimized"]["integrated_effective_mass"] = m * 1.001;
    const auto r = expect_with(moved);
    CHECK(r.exit_code == 4);
    const auto lines = moved_lines(r.err);
    REQUIRE(lines.size() == 1);
    CHECK(lines[0].rfind("optimized.integrated_effective_mass: stored ", 0) == 0);
    CHECK(contains(lines[0], json(m * 1.001).dump()));
    CHECK(contains(lines[0], ", now " + json(m).dump()));
    CHECK(contains(r.err, kErrorPrefix + " --expect stored.json: 1 value differs"));
    CHECK(r.out.find("With optimization") != std::string::npos);  // the table is still printed
  }
  {  // within --rtol passes; a tighter --rtol fails
    json moved = base;
    moved["optimized"]["integrated_effective_mass"] = m * (1 + 1e-8);
    CHECK(expect_with(moved).exit_code == 0);  // default rtol 1e-6
    const auto tight = expect_with(moved, {"--rtol", "1e-10"});
    CHECK(tight.exit_code == 4);
    CHECK(moved_lines(tight.err).size() == 1);
  }
  {  // array entries, missing and extra keys, strings are differences too
    json moved = base;
    moved["baseline"]["capture_configuration_deg"][1] =
        base.at("baseline").at("capture_configuration_deg")[1].get<double>() + 0.5;
    moved["no_such_run"] = {{"rows", 3}};              // stored only
    moved.erase("force_reduction_percent");            // now only
    moved["optimized"]["task"] = "pose";               // a string
    moved["optimized"]["capture_point"] = {1.0, 2.0};  // another length
    const auto r = expect_with(moved);
    CHECK(r.exit_code == 4);
    const auto lines = moved_lines(r.err);
    CHECK(lines.size() == 5);
    const std::string all = r.err;
    CHECK(contains(all, "baseline.capture_configuration_deg[1]: stored "));
    CHECK(contains(all, "no_such_run: stored an object of 1 keys, now missing"));
    CHECK(contains(all, "force_reduction_percent: stored missing, now "));
    CHECK(contains(all, "optimized.task: stored \"pose\", now \"position\""));
    CHECK(contains(all, "optimized.capture_point: stored 2 entries, now 3"));
    CHECK(contains(all, "5 values differ"));
  }
  {  // the version and the resolved scenario are inputs: not compared
    json other = base;
    other["version"] = "0.0.0";
    other["scenario"]["urdf"] = "/elsewhere/paper_3dof.urdf";
    CHECK(expect_with(other).exit_code == 0);
  }
  {  // wall-clock times and the optimizers' work counters are not results: not compared
    json other = base;
    REQUIRE(other["optimized"].contains("damped_evaluations"));
    other["optimized"]["damped_evaluations"] = other["optimized"]["damped_evaluations"].get<long>() + 7;
    other["baseline"]["damped_evaluations"] = 0;
    CHECK(expect_with(other).exit_code == 0);
    other["optimized"]["steps"] = other["optimized"]["steps"].get<long>() + 1;  // a result: still compared
    const auto r = expect_with(other);
    CHECK(r.exit_code == 4);
    CHECK(moved_lines(r.err).size() == 1);
  }
  {  // --atol: the floor for values near zero
    json moved = base;
    // tracking_error is ~1e-11 m (round-off of the tracking): 1e-10 differs by a factor of ten
    // but by less than the default atol of 1e-9
    moved["optimized"]["tracking_error"] = 1e-10;
    CHECK(expect_with(moved).exit_code == 0);
    CHECK(expect_with(moved, {"--atol", "0"}).exit_code == 4);
  }
}

TEST_CASE("expect: a bad baseline or tolerance is exit 2 naming it", "[output][expect]") {
  TempDir tmp;
  write_text(tmp / "not_json.json", "{\"baseline\": ");
  write_text(tmp / "array.json", "[1, 2]");
  struct Case {
    Args args;
    std::vector<std::string> names;
  };
  const std::vector<Case> cases{
      {{"--quiet", "--expect", "missing.json"}, {"--expect", "missing.json", "cannot open"}},
      {{"--quiet", "--expect", "not_json.json"}, {"--expect", "not_json.json", "not a JSON file"}},
      {{"--quiet", "--expect", "array.json"}, {"--expect", "array.json", "JSON object"}},
      {{"--quiet", "--expect", "."}, {"--expect", "."}},
      {{"--quiet", "--expect", "array.json", "--rtol", "-1"}, {"--rtol", "-1"}},
      {{"--quiet", "--expect", "array.json", "--atol", "nan"}, {"--atol"}},
      {{"--quiet", "--rtol", "-1e-3"}, {"--rtol", "-0.001"}},  // checked without --expect too
  };
  for (const auto& c : cases) {
    const auto r = cli(c.args, tmp.str());
    INFO(r.err);
    CHECK(r.exit_code == 2);
    check_one_error_line(r, c.names);
    CHECK(r.out.empty());  // found before the work: no table
  }
}

TEST_CASE("expect: expect and rtol as scenario keys, expect relative to the scenario file",
          "[output][expect]") {
  TempDir tmp;
  fs::create_directory(tmp.path() / "s");
  // the paper's scenario with an absolute URDF path and the two keys
  std::string toml = read_file(kScenario3);
  const std::string key = "urdf = \"paper_3dof.urdf\"";
  REQUIRE(contains(toml, key));
  toml.replace(toml.find(key), key.size(), "urdf = \"" + kUrdf3 + "\"\nexpect = \"base.json\"\nrtol = 1e-9");
  write_text(tmp / "s/scenario.toml", toml);
  REQUIRE(cli({"--config", kScenario3, "--quiet", "--json", tmp / "s/base.json"}, tmp.str()).exit_code == 0);
  const auto ok = cli({"--config", "s/scenario.toml", "--quiet"}, tmp.str());  // run from another folder
  INFO(ok.err);
  CHECK(ok.exit_code == 0);

  json moved = json::parse(read_file(tmp / "s/base.json"));
  const double m = moved["baseline"]["integrated_effective_mass"].get<double>();
  moved["baseline"]["integrated_effective_mass"] = m * (1 + 1e-7);  // inside 1e-6, outside the file's 1e-9
  write_text(tmp / "s/base.json", moved.dump());
  const auto r = cli({"--config", "s/scenario.toml", "--quiet"}, tmp.str());
  CHECK(r.exit_code == 4);
  CHECK(contains(r.err, "baseline.integrated_effective_mass: stored "));
  CHECK(cli({"--config", "s/scenario.toml", "--quiet", "--rtol", "1e-6"}, tmp.str()).exit_code ==
        0);  // flag wins
}

}  // namespace test_output
