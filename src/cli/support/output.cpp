#include "support/output.hpp"

#include "support/progress.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <random>

namespace ffsr::cli {

using detail::str;

// --- output files ---------------------------------------------------------------------------------

namespace {

struct OutputSpec {
  std::string flag, path;
  const std::string* content;
};

enum class OutputKind { Stdout, Direct, Regular };

/// "path (--flag)", or the path alone when no flag is known; standard output is named as such.
std::string output_name(const OutputSpec& o) {
  if (is_stdout_name(o.path))
    return o.flag.empty() ? "standard output" : str("standard output (", o.flag, " ", o.path, ")");
  return o.flag.empty() ? o.path : str(o.path, " (", o.flag, ")");
}

[[noreturn]] void throw_write_error(const std::string& name, int err,
                                    const char* what = "cannot write the output file") {
  std::string msg = str(name, ": ", what);
  if (err != 0) msg += str(": ", std::strerror(err));
  if (err == EPIPE) msg += " (the reader closed the pipe)";
  throw InputError(msg);
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

/// What `path` is, following symbolic links one hop at a time (so that a dangling link gives the
/// file it names). Regular: `final_path` is the file to replace atomically (the link's target).
OutputKind resolve_output(const std::string& path, const std::string& name, std::string& final_path) {
  if (is_stdout_name(path)) return OutputKind::Stdout;
  std::string p = path;
  bool alias = false;  // a name of an open file descriptor: never replaced
  for (int hop = 0;; ++hop) {
    alias = alias || starts_with(p, "/proc/") || starts_with(p, "/dev/fd/") || p == "/dev/stdout" ||
            p == "/dev/stderr";
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno != ENOENT) throw_write_error(name, errno);
      final_path = p;  // a new file (a missing directory is reported when the file is created)
      return alias ? OutputKind::Direct : OutputKind::Regular;
    }
    if (S_ISLNK(st.st_mode)) {
      if (hop >= 40) throw_write_error(name, ELOOP);
      std::error_code ec;
      const std::filesystem::path target = std::filesystem::read_symlink(p, ec);
      if (ec) throw_write_error(name, ec.value());
      p = target.is_absolute() ? target.string() : (std::filesystem::path(p).parent_path() / target).string();
      continue;
    }
    if (S_ISDIR(st.st_mode))
      throw InputError(str(name, ": cannot write the output file (it is a directory)"));
    final_path = p;
    return S_ISREG(st.st_mode) && !alias ? OutputKind::Regular : OutputKind::Direct;
  }
}

/// Writes all of `content` to `fd`; returns 0 or the errno of the failing write.
int write_all(int fd, const std::string& content) {
  const char* data = content.data();
  size_t left = content.size();
  while (left > 0) {
    const ssize_t k = ::write(fd, data, left);
    if (k < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += k;
    left -= static_cast<size_t>(k);
  }
  return 0;
}

/// Creates a temporary file next to `final_path` (with the mode of the file it will replace) and
/// returns its descriptor, its name in `tmp`; -1 with errno set (and `tmp` empty) on failure.
int open_temporary(const std::string& final_path, std::string& tmp) {
  static thread_local std::random_device rd;
  int fd = -1;
  for (int attempt = 0; fd < 0 && attempt < 100; ++attempt) {
    tmp = final_path + ".tmp-" + std::to_string(rd());
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const int err = errno;
    tmp.clear();
    errno = err;
    return -1;
  }
  struct stat st {};
  if (::stat(final_path.c_str(), &st) == 0) (void)::fchmod(fd, st.st_mode & 07777);  // keep the mode
  return fd;
}

/// Opens a direct output (a FIFO, a device; standard output is descriptor 1, flushed first).
/// Returns the descriptor or -1 with errno set.
int open_direct(OutputKind kind, const std::string& final_path) {
  if (kind == OutputKind::Stdout) {
    std::cout.flush();
    std::fflush(stdout);
    return 1;
  }
  return ::open(final_path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
}

/// The outputs of one write: what each is, where it goes, its temporary file. Destroyed before the
/// renames (a failure), it removes the temporary files.
struct OutputPlan {
  const std::vector<OutputSpec>& outputs;
  std::vector<OutputKind> kinds;
  std::vector<std::string> finals, tmps;
  explicit OutputPlan(const std::vector<OutputSpec>& o) : outputs(o), finals(o.size()), tmps(o.size()) {}
  OutputPlan(const OutputPlan&) = delete;
  OutputPlan& operator=(const OutputPlan&) = delete;
  ~OutputPlan() {
    for (const auto& t : tmps)
      if (!t.empty()) ::unlink(t.c_str());
  }
  [[noreturn]] void fail(size_t i, int err, const char* what = "cannot write the output file") const {
    throw_write_error(output_name(outputs[i]), err, what);
  }
};

/// 1. What each output is (nothing is written when one of them cannot be); one on standard output.
void resolve_outputs(OutputPlan& p) {
  const OutputSpec* to_stdout = nullptr;
  for (size_t i = 0; i < p.outputs.size(); ++i) {
    p.kinds.push_back(resolve_output(p.outputs[i].path, output_name(p.outputs[i]), p.finals[i]));
    if (p.kinds.back() != OutputKind::Stdout) continue;
    if (to_stdout != nullptr)
      throw InputError(str(output_name(*to_stdout), " and ", output_name(p.outputs[i]),
                           ": only one output can go to standard output"));
    to_stdout = &p.outputs[i];
  }
}

/// 2. Regular files: their content into temporary files next to their targets.
void write_temporaries(OutputPlan& p) {
  for (size_t i = 0; i < p.outputs.size(); ++i) {
    if (p.kinds[i] != OutputKind::Regular) continue;
    const int fd = open_temporary(p.finals[i], p.tmps[i]);
    if (fd < 0) p.fail(i, errno);
    int err = write_all(fd, *p.outputs[i].content);
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) p.fail(i, err);
  }
}

/// 3. Standard output, FIFOs, devices: written directly, never replaced.
void write_direct(OutputPlan& p) {
  for (size_t i = 0; i < p.outputs.size(); ++i) {
    if (p.kinds[i] == OutputKind::Regular) continue;
    const int fd = open_direct(p.kinds[i], p.finals[i]);
    int err = fd < 0 ? errno : 0;
    if (err == 0) err = write_all(fd, *p.outputs[i].content);
    if (fd != 1 && fd >= 0 && ::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) p.fail(i, err);
  }
}

/// 4. The renames of the temporary files into place.
void rename_temporaries(OutputPlan& p) {
  for (size_t i = 0; i < p.outputs.size(); ++i) {
    if (p.kinds[i] != OutputKind::Regular) continue;
    if (::rename(p.tmps[i].c_str(), p.finals[i].c_str()) != 0)
      p.fail(i, errno, "cannot write the output file (rename failed)");
    p.tmps[i].clear();
  }
}

/// The writer behind Outputs, write_file_atomic and write_files_atomic. Reads the file system.
/// Writes: regular files via temporary files and rename (all or nothing), the others directly.
void write_outputs(const std::vector<OutputSpec>& outputs) {
  OutputPlan plan(outputs);
  resolve_outputs(plan);
  write_temporaries(plan);
  write_direct(plan);
  rename_temporaries(plan);
}

/// The file `path` names, for telling whether two outputs go to one file: the absolute path with
/// "." and ".." resolved and the symbolic links of its existing part followed. Empty for standard
/// output and character devices (/dev/null takes any number of outputs).
std::string file_identity(const std::string& path) {
  namespace fs = std::filesystem;
  if (is_stdout_name(path)) return {};
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode)) return {};
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) return path;
  const fs::path canonical = fs::weakly_canonical(p, ec);
  return (ec ? p.lexically_normal() : canonical).string();
}

std::string two_outputs_error(const std::string& a, const std::string& b) {
  return str(a, " and ", b, ": two outputs to one file");
}

}  // namespace

bool is_stdout_name(const std::string& path) {
  return path == "-" || path == "/dev/stdout" || path == "/dev/fd/1" || path == "/proc/self/fd/1";
}

Outputs::Outputs() = default;
Outputs::~Outputs() = default;  // the staged files and the streams' temporary files are removed
Outputs::Outputs(Outputs&&) noexcept = default;
Outputs& Outputs::operator=(Outputs&&) noexcept = default;

void Outputs::check_distinct(const std::string& shown, const std::string& path) const {
  const std::string id = file_identity(path);
  if (id.empty()) return;
  for (const auto& it : items_)
    if (file_identity(it.path) == id)
      throw InputError(two_outputs_error(it.given_as + " " + it.path, shown));
  for (const auto& s : streams_)
    if (file_identity(s->path()) == id)
      throw InputError(two_outputs_error(s->flag() + " " + s->path(), shown));
}

void Outputs::add(const std::string& flag, const std::string& path, const std::string& given_as) {
  if (path.empty()) return;
  const std::string name = given_as.empty() ? flag : given_as;
  if (is_stdout_name(path)) claim_stdout(name + " " + path);
  check_distinct(name + " " + path, path);
  items_.push_back({flag, name, path, {}, false});
}

std::vector<std::string> Outputs::stage(StagedFiles files) {
  std::vector<std::string> targets = files.targets();
  for (const std::string& target : targets)
    check_distinct(str(files.flag(), " ", files.dir(), " (", target, ")"), target);
  staged_.push_back(std::move(files));
  return targets;
}

StreamingOutput& Outputs::stream(const std::string& flag, const std::string& path) {
  if (is_stdout_name(path)) claim_stdout(flag + " " + path);
  check_distinct(flag + " " + path, path);
  streams_.push_back(std::make_unique<StreamingOutput>(flag, path));
  return *streams_.back();
}

void Outputs::claim_stdout(const std::string& flag) {
  if (!stdout_flag_.empty())
    throw InputError(str(stdout_flag_, " and ", flag, ": only one output can go to standard output"));
  stdout_flag_ = flag;
}

bool Outputs::requested(const std::string& flag) const {
  for (const auto& it : items_)
    if (it.flag == flag) return true;
  return false;
}

std::ostream& Outputs::table() const {
  static std::ostream nowhere(nullptr);  // no buffer: writes are dropped
  if (!uses_stdout()) return std::cout;
  return quiet() ? nowhere : std::cerr;
}

void Outputs::set(const std::string& flag, std::string content) {
  for (auto& it : items_)
    if (it.flag == flag) {
      it.content = std::move(content);
      it.has_content = true;
    }
}

void Outputs::write() {
  std::vector<OutputSpec> specs;
  for (const auto& it : items_)
    if (it.has_content) specs.push_back({it.given_as, it.path, &it.content});
  OutputPlan plan(specs);
  resolve_outputs(plan);
  write_temporaries(plan);
  for (auto& s : streams_) s->finish();
  write_direct(plan);
  // every output is produced: the renames
  rename_temporaries(plan);
  for (auto& s : streams_) s->commit();
  for (auto& f : staged_) f.commit();
}

StreamingOutput::StreamingOutput(const std::string& flag, const std::string& path)
    : flag_(flag), path_(path), name_(output_name({flag, path, nullptr})) {
  const OutputKind kind = resolve_output(path, name_, final_);
  fd_ = kind == OutputKind::Regular ? open_temporary(final_, tmp_) : open_direct(kind, final_);
  if (fd_ < 0) throw_write_error(name_, errno);
  buffer_.reserve(kBuffer);
}

StreamingOutput::~StreamingOutput() {
  if (fd_ > 1) ::close(fd_);
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
}

void StreamingOutput::write(const char* data, size_t n) {
  if (err_ != 0) return;  // reported by commit()
  buffer_.append(data, n);
  if (buffer_.size() >= kBuffer) flush_buffer();
}

void StreamingOutput::flush_buffer() {
  if (err_ == 0) err_ = write_all(fd_, buffer_);
  buffer_.clear();
}

void StreamingOutput::finish() {
  if (!finished_) {
    flush_buffer();
    if (fd_ > 1 && ::close(fd_) != 0 && err_ == 0) err_ = errno;
    fd_ = -1;
    finished_ = true;
  }
  if (err_ != 0) throw_write_error(name_, err_);
}

void StreamingOutput::commit() {
  finish();
  if (tmp_.empty()) return;  // written in place: standard output, a FIFO, a device
  if (::rename(tmp_.c_str(), final_.c_str()) != 0)
    throw_write_error(name_, errno, "cannot write the output file (rename failed)");
  tmp_.clear();
}

void write_file_atomic(const std::string& path, const std::string& content) {
  write_outputs({{"", path, &content}});
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<OutputSpec> specs;
  for (const auto& [path, content] : files) specs.push_back({"", path, &content});
  write_outputs(specs);
}

void flush_stdout() {
  errno = 0;
  std::cout.flush();
  const bool failed = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout);
  if (failed) {
    // errno names the cause when this flush failed; an earlier failed write may have lost it
    if (errno == 0)
      throw InputError("standard output: cannot write (a closed pipe, a full disk or an I/O error)");
    throw_write_error("standard output", errno, "cannot write");
  }
}

// --- the output flags ---------------------------------------------------------------------------------

Outputs OutputKeys::outputs() const {
  Outputs o;
  o.add("--json", json);
  o.add("--csv", csv, csv_flag);
  return o;
}

void add_output_flags(CLI::App& app, OutputKeys& keys, const OutputHelp& help) {
  app.add_option("--json", keys.json, str(help.json, " ('-' or no FILE: standard output)"))
      ->expected(0, 1)
      ->default_str("-")  // --json alone: standard output
      ->option_text("[FILE]");
  if (help.csv) {
    app.add_option("--csv", keys.csv, str(help.csv, " ('-': standard output)"))->option_text("FILE");
    if (help.csv_alias)  // the same output under an older name; messages name the flag as given
      app.add_option(help.csv_alias, keys.csv, "Same as --csv")
          ->option_text("FILE")
          ->each([&keys, alias = std::string(help.csv_alias)](const std::string&) { keys.csv_flag = alias; });
  }
  if (help.plot) {
    app.add_option("--plot", keys.plot, str(help.plot, " into this (existing) folder"))->option_text("DIR");
    app.add_option("--plot-format", keys.plot_format, "Figure format: png, svg or pdf")->capture_default_str();
  }
  // --quiet alone is true; --quiet=VALUE takes true or false only, like every boolean key
  const CLI::Validator true_or_false(
      [](std::string& v) {
        return v == "true" || v == "false" ? std::string() : str("expected true or false, got '", v, "'");
      },
      "true|false");
  app.add_flag("--quiet", keys.quiet, "Nothing on standard error but an error: no progress line, no warning")
      ->check(true_or_false);
}

}  // namespace ffsr::cli
