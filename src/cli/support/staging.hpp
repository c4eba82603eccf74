// src/cli/support/staging.hpp -- files produced before they are put in place: a scratch folder
// inside their destination folder, whose files Outputs::write (support/output.hpp) moves into the
// folder together with the run's other outputs, or nothing at all.
#pragma once

#include "ffsr/errors.hpp"

#include <stdlib.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace ffsr::cli {

/// Files drawn or written into a scratch folder (".ffsr-stage-XXXXXX" inside `dir`, so that the
/// final rename stays within one file system) and moved into `dir` by Outputs::write once every
/// output of the run was produced. Destroyed with files still staged (the run failed, or another
/// output could not be written), it removes the scratch folder and everything in it: `dir` is left
/// as it was. Header-only: the figures' library (figures/plot.cpp) stages into it too.
class StagedFiles {
 public:
  StagedFiles() = default;
  /// Creates the scratch folder inside `dir`; InputError naming `flag` and `dir` when it cannot.
  StagedFiles(const std::string& dir, const std::string& flag) : dir_(dir), flag_(flag) {
    std::string tmpl = (std::filesystem::path(dir) / ".ffsr-stage-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr)
      throw InputError(detail::str(flag, ": cannot write into folder '", dir, "'"));
    scratch_ = tmpl;
  }
  ~StagedFiles() { discard(); }
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  StagedFiles(StagedFiles&& o) noexcept
      : dir_(std::move(o.dir_)), flag_(std::move(o.flag_)), scratch_(std::move(o.scratch_)),
        names_(std::move(o.names_)) {
    o.scratch_.clear();
    o.names_.clear();
  }
  StagedFiles& operator=(StagedFiles&& o) noexcept {
    if (this != &o) {
      discard();
      dir_ = std::move(o.dir_);
      flag_ = std::move(o.flag_);
      scratch_ = std::move(o.scratch_);
      names_ = std::move(o.names_);
      o.scratch_.clear();
      o.names_.clear();
    }
    return *this;
  }

  /// The flag the files were asked for by (e.g. "--plot"), for messages.
  const std::string& flag() const { return flag_; }
  /// The destination folder, as given.
  const std::string& dir() const { return dir_; }
  /// The scratch folder: write the files here under the names given to add().
  const std::filesystem::path& scratch() const { return scratch_; }
  /// Registers the file `name` of the scratch folder, to become `dir/name`.
  void add(const std::string& name) { names_.push_back(name); }
  const std::vector<std::string>& names() const { return names_; }
  /// The files' final paths, `dir/name`, in the order of add().
  std::vector<std::string> targets() const {
    std::vector<std::string> t;
    for (const auto& n : names_) t.push_back((std::filesystem::path(dir_) / n).string());
    return t;
  }
  /// Moves the staged files into `dir` (the last step of Outputs::write); InputError naming the file
  /// when a rename fails. The scratch folder is removed afterwards.
  void commit() {
    namespace fs = std::filesystem;
    for (const auto& n : names_) {
      std::error_code ec;
      const fs::path to = fs::path(dir_) / n;
      fs::rename(scratch_ / n, to, ec);
      if (ec) throw InputError(detail::str(flag_, ": cannot write ", to.string(), ": ", ec.message()));
    }
    names_.clear();
    discard();
  }
  /// Removes the scratch folder and whatever is still in it.
  void discard() noexcept {
    if (scratch_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(scratch_, ec);
    scratch_.clear();
  }

 private:
  std::string dir_, flag_;
  std::filesystem::path scratch_;
  std::vector<std::string> names_;
};

}  // namespace ffsr::cli
