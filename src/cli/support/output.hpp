// src/cli/support/output.hpp -- the command's outputs: the output flags every subcommand takes, and
// the one writer of files and standard output (atomic, all or nothing).
#pragma once

#include "ffsr/scenario/scenario.hpp"
#include "support/staging.hpp"

#include <nlohmann/json.hpp>

#include <CLI/CLI.hpp>

#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace ffsr::cli {

/// Output files, as people name them in a shell. Every subcommand writes its outputs through
/// `Outputs` (or the two functions below, which use the same writer):
///  - "-" (also /dev/stdout, /dev/fd/1, /proc/self/fd/1) is standard output; at most one output of a
///    run may be standard output, and the human-readable table then goes to standard error;
///  - a path that is not a regular file (a FIFO, a device such as /dev/null, anything under /proc or
///    /dev/fd) is opened and written directly, never replaced;
///  - a symbolic link is followed and its final target is replaced atomically (a temporary file in
///    the target's directory, then rename), so the link stays a link;
///  - a regular file (or a new path) is written to a temporary file next to it and renamed into place
///    when every output of the run is written: all or nothing;
///  - the figures of --plot are drawn into a scratch folder inside their folder (StagedFiles, given
///    to stage()) and the streamed CSV of map into a temporary file (stream()); write() moves them
///    into place with the others, after every output was produced;
///  - two outputs to one file (the same path, ./F and F, a link and its target) are refused naming
///    both flags, like two outputs to standard output (a character device such as /dev/null excepted).
/// Every failure (missing directory, a directory in the way, full disk, I/O error, a reader that
/// closed the pipe: SIGPIPE is ignored by main) throws InputError naming the flag and the file and
/// leaves no partial regular file, no temporary file and no figure behind: an Outputs destroyed
/// before write() succeeded removes what it staged.
class StreamingOutput;
class Outputs {
 public:
  /// Registers the output of `flag` (for example "--json") at `path`; an empty path: not requested.
  /// `given_as`: the name messages use when the flag was given under another name (contact's
  /// --series for --csv); empty: `flag`. Throws InputError naming both flags when a second output
  /// names standard output.
  void add(const std::string& flag, const std::string& path, const std::string& given_as = {});
  /// `flag` prints on standard output itself (for example `contact --json`); same check as add.
  void claim_stdout(const std::string& flag);
  bool requested(const std::string& flag) const;
  /// True when an output goes to standard output.
  bool uses_stdout() const { return !stdout_flag_.empty(); }
  /// Where the human-readable table goes: standard error when an output is standard output (nowhere
  /// then with --quiet: nothing on standard error but an error).
  std::ostream& table() const;
  /// Sets the content of the output registered by `flag` (ignored when the flag was not requested).
  void set(const std::string& flag, std::string content);
  /// Files produced before the write (the figures of --plot), moved into their folder by write().
  /// Throws InputError naming both flags when one of them is the file of another output. Returns
  /// the files' final paths.
  std::vector<std::string> stage(StagedFiles files);
  /// Opens the output of `flag` at `path` written as it is produced (see StreamingOutput), committed
  /// by write(); same checks as add. The reference stays valid as long as this object.
  StreamingOutput& stream(const std::string& flag, const std::string& path);
  /// Writes every registered output that has content: regular files to temporary files first (and
  /// the streamed outputs closed), then the direct outputs (standard output, FIFOs, devices), then
  /// the renames of the temporary files, of the streamed outputs and of the staged files.
  void write();

  Outputs();
  ~Outputs();
  Outputs(Outputs&&) noexcept;
  Outputs& operator=(Outputs&&) noexcept;

 private:
  struct Item {
    std::string flag, given_as, path, content;
    bool has_content = false;
  };
  /// Refuses the output `shown` (its flag and path, for the message) at `path` when an output
  /// registered before goes to the same file.
  void check_distinct(const std::string& shown, const std::string& path) const;
  std::vector<Item> items_;
  std::vector<std::unique_ptr<StreamingOutput>> streams_;
  std::vector<StagedFiles> staged_;
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
  /// Appends `n` bytes (buffered; a write error is reported by finish() or commit()).
  void write(const char* data, size_t n);
  /// Flushes and closes the file; InputError naming the flag and the file when a write failed.
  void finish();
  /// finish(), then renames the temporary file into place.
  void commit();
  /// The file written, after symbolic links (empty for standard output).
  const std::string& final_path() const { return final_; }
  const std::string& flag() const { return flag_; }
  const std::string& path() const { return path_; }

 private:
  static constexpr size_t kBuffer = 1 << 16;
  void flush_buffer();
  std::string flag_, path_, name_, final_, tmp_, buffer_;
  int fd_ = -1;
  int err_ = 0;
  bool finished_ = false;
};
/// Flushes standard output and throws InputError ("standard output: cannot write ...") when a write to
/// it failed (a closed pipe, a full disk). main calls it after every successful action.
void flush_stdout();

/// The output flags every subcommand takes (docs/command.md, "Conventions"): `--json [FILE]` (no FILE
/// or '-': standard output), `--csv FILE` where the subcommand has series, `--plot DIR` and
/// `--plot-format` where it draws, and `--quiet`. The subcommands that run a scenario file also take
/// them as keys of the file (a flag overrides the file).
struct OutputKeys {
  std::string json, csv, plot, plot_format = "png";
  bool quiet = false;
  std::string csv_flag = "--csv";  ///< the name the CSV was asked for by (contact also takes --series)
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
  /// The files of --json and --csv (Outputs::add: two outputs on standard output are refused here,
  /// before any work).
  Outputs outputs() const;
};

/// What a subcommand writes, for the help of its output flags: --json always; --csv and --plot when
/// the text is not null. `csv_alias`: a second name of --csv (contact's --series).
struct OutputHelp {
  const char* json;
  const char* csv = nullptr;
  const char* plot = nullptr;
  const char* csv_alias = nullptr;
};
/// Registers the output flags of OutputKeys on `app`.
void add_output_flags(CLI::App& app, OutputKeys& keys, const OutputHelp& help);

/// Calls set(name, text, flag) for every command key the scenario file holds (ScenarioKeys::extra:
/// json, csv, plot, ...) whose flag was not given on the command line: a flag overrides the file.
/// `set` parses and checks the text (InputError "--key: ..."); the error is located in the file and
/// names the key as written there ("scenario FILE:LINE: key: ...", located_key_message).
template <class Set>
void for_each_file_key(const ScenarioKeys& keys, const CLI::App& app, Set&& set) {
  for (const auto& [name, text] : keys.extra) {
    const std::string flag = "--" + name;
    if (app.get_option(flag)->count() > 0) continue;
    try {
      set(name, text, flag);
    } catch (const InputError& e) {
      throw InputError(located_key_message(keys, e.what()));
    }
  }
}

}  // namespace ffsr::cli
