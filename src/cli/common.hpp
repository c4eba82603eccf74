// src/cli/common.hpp -- options shared by the subcommands, parsing helpers and output files.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/ffsr.hpp"
#include "model_options.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace ffsr::cli {

/// Exit codes: 2 for bad input (arguments, files, models) and for an output that cannot be written
/// (including a reader that closed the pipe), 3 for a numerical failure, 4 when the result moved away
/// from the --expect baseline.
constexpr int kExitInput = 2;
constexpr int kExitNumerical = 3;
constexpr int kExitRegression = 4;

/// Parses "a,b,c" into numbers; throws InputError naming `flag` on a bad or non-finite number or
/// when the count is not one of `counts` (empty: any count >= 1).
std::vector<double> parse_list(const std::string& text, const std::string& flag,
                               std::vector<size_t> counts = {});
Vector3 parse_vec3(const std::string& text, const std::string& flag);
/// A non-negative integer written in decimal digits (no sign, no exponent), or InputError naming `flag`.
std::uint64_t parse_count(const std::string& text, const std::string& flag);
/// --shard K/N: part K (counting from 0) of N.
struct Shard {
  std::uint64_t k = 0, n = 1;
};
/// Parses K/N (0 <= K < N); InputError naming --shard.
Shard parse_shard(const std::string& text);
double deg2rad(double deg);
double rad2deg(double rad);

/// The robot at one configuration, the target and the contact law that inspect, contact and map
/// evaluate: the keys of a scenario file (--config) or of the built-in scenario, then the scenario
/// keys given as flags (the robot and its start state, the bus, the target, the contact law), read,
/// checked and built by the library (ffsr/io/scenario.hpp) as for the main job. --urdf replaces the
/// robot: its joint angles (--joints-deg, then required) and end-effector come from the flags alone.
struct SubjectOptions {
  std::string config;
  ScenarioFlags flags;
  /// --config and the flags of the subject's keys; `also` adds keys of the key table (their flags).
  void add_to(CLI::App& app, const std::set<std::string>& also = {});
};

/// A robot at one configuration.
struct Robot {
  Model model;
  int end_effector = 0;
  BasePose base;
  Eigen::VectorXd theta;
  UrdfReport report;  ///< what the loader did to the file
};

/// What SubjectOptions describe, built.
struct Subject {
  ScenarioKeys keys;  ///< as resolved (the URDF path relative to the scenario file)
  Robot robot;
  Target target;              ///< at t = 0, with its spin and velocity
  ContactParams params;       ///< K, alpha, c_r, checked
  std::string law;            ///< the damping law's name as given (contact also takes 'all')
  double approach_speed = 0;  ///< m/s, finite (its sign is the subcommand's to judge)
  /// The joint models of the contact (contact-joints, armature; algorithm/joint_models.hpp); 'all'
  /// (contact: each model in turn) gives free. InputError naming the key.
  ContactJoints contact_joints() const;
  bool all_joint_models() const { return keys.contact_joints == "all"; }
};
/// Builds the subject; warns about every repair of the model. InputError naming the key or the file,
/// ModelError from the loader.
Subject load_subject(const SubjectOptions& options);

/// Output files, as people name them in a shell. Every subcommand writes its outputs through
/// `Outputs` (or the two functions below, which use the same writer):
///  - "-" (also /dev/stdout, /dev/fd/1, /proc/self/fd/1) is standard output; at most one output of a
///    run may be standard output, and the human-readable table then goes to standard error;
///  - a path that is not a regular file (a FIFO, a device such as /dev/null, anything under /proc or
///    /dev/fd) is opened and written directly, never replaced;
///  - a symbolic link is followed and its final target is replaced atomically (a temporary file in
///    the target's directory, then rename), so the link stays a link;
///  - a regular file (or a new path) is written to a temporary file next to it and renamed into place
///    when every output of the run is written: all or nothing.
/// Every failure (missing directory, a directory in the way, full disk, I/O error, a reader that
/// closed the pipe: SIGPIPE is ignored by main) throws InputError naming the flag and the file and
/// leaves no partial regular file and no temporary file behind.
class Outputs {
 public:
  /// Registers the output of `flag` (for example "--json") at `path`; an empty path: not requested.
  /// Throws InputError naming both flags when a second output names standard output.
  void add(const std::string& flag, const std::string& path);
  /// `flag` prints on standard output itself (for example `contact --json`); same check as add.
  void claim_stdout(const std::string& flag);
  bool requested(const std::string& flag) const;
  /// True when an output goes to standard output.
  bool uses_stdout() const { return !stdout_flag_.empty(); }
  /// Where the human-readable table goes: standard error when an output is standard output.
  std::ostream& table() const;
  /// Sets the content of the output registered by `flag` (ignored when the flag was not requested).
  void set(const std::string& flag, std::string content);
  /// Writes every registered output that has content: regular files to temporary files first, then
  /// the direct outputs (standard output, FIFOs, devices), then the renames.
  void write() const;

 private:
  struct Item {
    std::string flag, path, content;
    bool has_content = false;
  };
  std::vector<Item> items_;
  std::string stdout_flag_;
};

/// True for "-" and the names of the standard output file descriptor.
bool is_stdout_name(const std::string& path);
/// Writes a file (see Outputs for "-", FIFOs, devices and symbolic links); a regular file atomically.
/// Throws InputError naming the path when it cannot be written; never leaves a partial file behind.
void write_file_atomic(const std::string& path, const std::string& content);
/// Writes several files all or nothing (see Outputs); at most one may be standard output. A failure
/// removes the temporary files and throws InputError naming the path, so no regular output file of
/// the run is left behind.
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files);
/// An output written as it is produced (a large CSV), with the rules of Outputs: a regular file (or
/// a symbolic link's target) goes to a temporary file next to it, renamed into place by commit();
/// standard output, FIFOs and devices are written directly. Destroyed without commit() (the run
/// failed), it removes the temporary file: no partial regular file is left behind. Errors name the
/// flag and the file (InputError), from the constructor or from commit().
class StreamingOutput {
 public:
  StreamingOutput(const std::string& flag, const std::string& path);
  ~StreamingOutput();
  StreamingOutput(const StreamingOutput&) = delete;
  StreamingOutput& operator=(const StreamingOutput&) = delete;
  /// Appends `n` bytes (buffered; a write error is reported by commit()).
  void write(const char* data, size_t n);
  /// Flushes, closes and renames the temporary file into place.
  void commit();

 private:
  static constexpr size_t kBuffer = 1 << 16;
  void flush_buffer();
  std::string name_, final_, tmp_, buffer_;
  int fd_ = -1;
  int err_ = 0;
};
/// Flushes standard output and throws InputError ("standard output: cannot write ...") when a write to
/// it failed (a closed pipe, a full disk). main calls it after every successful action.
void flush_stdout();

/// A progress line on stderr when it is a terminal, shown once a run has lasted a second
/// (`label` names the run). Call from one thread only.
struct Progress {
  explicit Progress(std::string label_, bool quiet = false, std::string unit_ = "points");
  /// "label run  42%".
  void operator()(double fraction);
  /// "label 1234/5678 points, 1.2e+06/s, 3 s left" (`unit` instead of "points").
  void operator()(unsigned long long done, unsigned long long total);

 private:
  std::string label, unit;
  std::chrono::steady_clock::time_point start;
  bool shown = false;
  bool enabled;
};

/// Matrix -> JSON array of rows.
nlohmann::json to_json(const Eigen::MatrixXd& m);
nlohmann::json to_json(const Eigen::VectorXd& v);

/// The output keys of the subcommands that run a scenario (the main job, robust): where the JSON,
/// the CSV and the figures go, and whether progress is shown. A flag or the scenario file sets them.
struct OutputKeys {
  std::string json, csv, plot, plot_format = "png";
  bool quiet = false;
  /// Sets output key `name` from the scenario file's text (`flag` names it in errors); false when
  /// `name` is not an output key.
  bool set_from_file(const std::string& name, const std::string& text, const std::string& flag) {
    if (name == "json")
      json = text;
    else if (name == "csv")
      csv = text;
    else if (name == "plot")
      plot = text;
    else if (name == "plot-format")
      plot_format = text;
    else if (name == "quiet")
      quiet = ffsr::detail::boolean_from_text(text, flag);
    else
      return false;
    return true;
  }
};

/// Calls set(name, text, flag) for every command key the scenario file holds (ScenarioKeys::extra:
/// json, csv, plot, ...) whose flag was not given on the command line: a flag overrides the file.
template <class Set>
void for_each_file_key(const ScenarioKeys& keys, const CLI::App& app, Set&& set) {
  for (const auto& [name, text] : keys.extra) {
    const std::string flag = "--" + name;
    if (app.get_option(flag)->count() > 0) continue;
    set(name, text, flag);
  }
}

}  // namespace ffsr::cli
