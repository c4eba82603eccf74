#include "common.hpp"
#include "scenario.hpp"

#include "ffsr/io/urdf.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>

#include <unistd.h>

namespace ffsr::cli {

using detail::str;

std::vector<double> parse_list(const std::string& text, const std::string& flag, std::vector<size_t> counts) {
  std::vector<double> out;
  std::string item;
  std::stringstream ss(text);
  if (text.empty()) throw InputError(str(flag, ": expected comma-separated numbers, got an empty value"));
  while (std::getline(ss, item, ',')) {
    const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    const std::string t = b == std::string::npos ? std::string() : item.substr(b, e - b + 1);
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size())
      throw InputError(str(flag, ": '", t, "' is not a number (in '", text, "')"));
    if (!std::isfinite(x) || errno == ERANGE)
      throw InputError(str(flag, ": '", t, "' is not a finite number (in '", text, "')"));
    out.push_back(x);
  }
  if (!text.empty() && text.back() == ',') throw InputError(str(flag, ": trailing comma in '", text, "'"));
  if (!counts.empty()) {
    bool ok = false;
    std::string expected;
    for (size_t c : counts) {
      ok = ok || out.size() == c;
      expected += (expected.empty() ? "" : " or ") + std::to_string(c);
    }
    if (!ok)
      throw InputError(str(flag, ": expected ", expected, " comma-separated numbers, got ", out.size(), " ('",
                           text, "')"));
  }
  return out;
}

Vector3 parse_vec3(const std::string& text, const std::string& flag) {
  const auto v = parse_list(text, flag, {3});
  return {v[0], v[1], v[2]};
}

std::uint64_t parse_count(const std::string& text, const std::string& flag) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(str(flag, ": expected a non-negative integer, got '", text, "'"));
  return std::stoull(text);
}

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw InputError(str("--shard: expected K/N, got '", text, "'"));
  Shard s;
  s.k = parse_count(text.substr(0, slash), "--shard");
  s.n = parse_count(text.substr(slash + 1), "--shard");
  if (s.n < 1) throw InputError("--shard: N must be at least 1");
  if (s.k >= s.n) throw InputError(str("--shard: K must be less than N (K counts from 0), got ", text));
  return s;
}

double deg2rad(double deg) { return deg * M_PI / 180.0; }
double rad2deg(double rad) { return rad * 180.0 / M_PI; }

namespace {

/// The keys of a subject (SubjectOptions): the robot and its start state, the bus and the loader, the
/// target and the contact law (the key table's groups).
const std::set<std::string>& subject_keys() {
  static const std::set<std::string> keys =
      scenario_key_names({KeyGroup::Robot, KeyGroup::Start, KeyGroup::Target, KeyGroup::Contact});
  return keys;
}

}  // namespace

void SubjectOptions::add_to(CLI::App& app, const std::set<std::string>& also) {
  app.add_option("--config", config,
                 "Scenario file (TOML) whose robot, start state, target and contact law to take; flags "
                 "override its keys (default: the built-in paper 3-DOF scenario)")
      ->check(CLI::ExistingFile);
  flags.add_to(app,
               [&also](const std::string& name) { return subject_keys().count(name) || also.count(name); });
}

Subject load_subject(const SubjectOptions& o) {
  Subject s;
  s.keys = command_scenario_keys(o.config, o.flags);
  ScenarioKeys& k = s.keys;
  if (o.flags.given("urdf")) {  // another robot: its end-effector and joint angles from the flags alone
    if (!o.flags.given("end-effector")) k.end_effector.clear();
    if (!o.flags.given("joints-deg"))
      throw InputError(
          "--joints-deg: required with --urdf (the robot's joint angles in degrees, URDF tree order)");
  }
  const EmbeddedUrdf embedded = builtin_urdf();
  s.robot.model = std::move(*ffsr::detail::model_of(k, &embedded, s.robot.report));
  warn_repairs(s.robot.report);
  CaptureProblem pb;
  ffsr::detail::start_of(k, s.robot.model, pb);
  s.robot.end_effector = s.robot.model.end_effector();
  s.robot.theta = pb.theta;
  s.robot.base = pb.base;
  s.target = ffsr::detail::target_of(k);
  s.params = {k.stiffness, k.exponent, k.restitution};  // validate names a non-finite value
  try {
    validate(s.params, "contact");
  } catch (const InputError& e) {
    throw InputError(std::string("--stiffness/--exponent/--restitution: ") + e.what());
  }
  s.law = k.model;
  s.approach_speed = ffsr::detail::finite(k.approach_speed, "approach-speed");
  return s;
}

ContactJoints Subject::contact_joints() const {
  const JointModel m =
      all_joint_models() ? JointModel::Free : parse_joint_model(keys.contact_joints, "--contact-joints");
  return {m, per_joint_values(keys.armature, robot.model, "--armature")};
}

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

/// The writer behind Outputs, write_file_atomic and write_files_atomic. Reads the file system.
/// Writes: regular files via temporary files and rename (all or nothing), the others directly.
void write_outputs(const std::vector<OutputSpec>& outputs) {
  // 1. what each output is (nothing is written when one of them cannot be)
  std::vector<OutputKind> kinds;
  std::vector<std::string> finals(outputs.size());
  const OutputSpec* to_stdout = nullptr;
  for (size_t i = 0; i < outputs.size(); ++i) {
    kinds.push_back(resolve_output(outputs[i].path, output_name(outputs[i]), finals[i]));
    if (kinds.back() != OutputKind::Stdout) continue;
    if (to_stdout != nullptr)
      throw InputError(str(output_name(*to_stdout), " and ", output_name(outputs[i]),
                           ": only one output can go to standard output"));
    to_stdout = &outputs[i];
  }
  // 2. regular files: temporary files next to their targets
  std::vector<std::string> tmps(outputs.size());
  auto remove_tmps = [&tmps] {
    for (const auto& t : tmps)
      if (!t.empty()) ::unlink(t.c_str());
  };
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (kinds[i] != OutputKind::Regular) continue;
    const int fd = open_temporary(finals[i], tmps[i]);
    if (fd < 0) {
      const int err = errno;
      remove_tmps();
      throw_write_error(output_name(outputs[i]), err);
    }
    int err = write_all(fd, *outputs[i].content);
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) {
      remove_tmps();
      throw_write_error(output_name(outputs[i]), err);
    }
  }
  // 3. standard output, FIFOs, devices: written directly, never replaced
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (kinds[i] == OutputKind::Regular) continue;
    const int fd = open_direct(kinds[i], finals[i]);
    int err = fd < 0 ? errno : 0;
    if (err == 0) err = write_all(fd, *outputs[i].content);
    if (fd != 1 && fd >= 0 && ::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) {
      remove_tmps();
      throw_write_error(output_name(outputs[i]), err);
    }
  }
  // 4. the renames
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (kinds[i] != OutputKind::Regular) continue;
    if (::rename(tmps[i].c_str(), finals[i].c_str()) != 0) {
      const int err = errno;
      remove_tmps();
      throw_write_error(output_name(outputs[i]), err, "cannot write the output file (rename failed)");
    }
    tmps[i].clear();
  }
}

}  // namespace

bool is_stdout_name(const std::string& path) {
  return path == "-" || path == "/dev/stdout" || path == "/dev/fd/1" || path == "/proc/self/fd/1";
}

void Outputs::add(const std::string& flag, const std::string& path) {
  if (path.empty()) return;
  if (is_stdout_name(path)) claim_stdout(flag + " " + path);
  items_.push_back({flag, path, {}, false});
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

std::ostream& Outputs::table() const { return uses_stdout() ? std::cerr : std::cout; }

void Outputs::set(const std::string& flag, std::string content) {
  for (auto& it : items_)
    if (it.flag == flag) {
      it.content = std::move(content);
      it.has_content = true;
    }
}

void Outputs::write() const {
  std::vector<OutputSpec> specs;
  for (const auto& it : items_)
    if (it.has_content) specs.push_back({it.flag, it.path, &it.content});
  write_outputs(specs);
}

StreamingOutput::StreamingOutput(const std::string& flag, const std::string& path)
    : name_(output_name({flag, path, nullptr})) {
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

void StreamingOutput::commit() {
  flush_buffer();
  if (fd_ > 1 && ::close(fd_) != 0 && err_ == 0) err_ = errno;
  fd_ = -1;
  if (err_ != 0) throw_write_error(name_, err_);
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

Progress::Progress(std::string label_, bool quiet, std::string unit_)
    : label(std::move(label_)),
      unit(std::move(unit_)),
      start(std::chrono::steady_clock::now()),
      enabled(!quiet && isatty(fileno(stderr)) != 0) {}

void Progress::operator()(double fraction) {
  if (!enabled) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (s < 1.0 && !shown) return;
  shown = true;
  std::fprintf(stderr, "\rffsr-optimize: %s run %3.0f%%", label.c_str(), fraction * 100.0);
  if (fraction >= 1.0) std::fprintf(stderr, "\n");
}

void Progress::operator()(unsigned long long done, unsigned long long total) {
  if (!enabled) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (s < 1.0 && !shown) return;
  shown = true;
  const double rate = s > 0 ? static_cast<double>(done) / s : 0.0;
  const double left = rate > 0 ? static_cast<double>(total - done) / rate : 0.0;
  std::fprintf(stderr, "\rffsr-optimize: %s %llu/%llu %s (%3.0f%%), %.3g %s/s, %.0f s left   ", label.c_str(),
               done, total, unit.c_str(),
               total ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0, rate,
               unit.c_str(), left);
  if (done >= total) std::fprintf(stderr, "\n");
}

nlohmann::json to_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json to_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

}  // namespace ffsr::cli
