// python/src/arguments.hpp -- the argument readers of ffsr._ffsr (arguments.cpp): an array argument
// that a call only reads is taken as numpy.asarray(x, dtype=numpy.float64) takes it, without a copy when
// it is already float64 and C-contiguous; its shape and values are checked with messages that name the
// function and the argument. The arrays a call writes into are read by the controller (controller.cpp).
#pragma once

#include "common.hpp"

#include <string>
#include <utility>
#include <vector>

namespace ffsr::python {

/// Whether a reader refuses NaN and infinity (InputError naming the entry), or leaves the values to
/// the call (the controller's inputs: a bad value there is a fault status, not an exception).
enum class Values { Finite, Any };

/// A vector argument: a view of the caller's float64 array, or of the converted copy it keeps.
class VecIn {
 public:
  VecIn(nb::handle h, const char* where, const char* what, Values values = Values::Finite);
  Eigen::Map<const Eigen::VectorXd> map() const { return {data_, size_}; }
  Eigen::Index size() const { return size_; }
  /// Exactly `n` entries, else InputError "<where>: <what> has <size> entries, expected <n>".
  const VecIn& require(Eigen::Index n) const;

 private:
  nb::ndarray<nb::ro> array_;  ///< the float64 array read (the caller's, or numpy's conversion of it)
  const double* data_ = nullptr;
  Eigen::Index size_ = 0;
  const char *where_, *what_;
};

/// A 2-D argument, row-major (C order): a view of the caller's float64 array or of the converted copy.
class MatIn {
 public:
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  MatIn(nb::handle h, const char* where, const char* what, Values values = Values::Finite);
  Eigen::Map<const RowMajor> map() const { return {data_, rows_, cols_}; }
  Eigen::Index rows() const { return rows_; }
  Eigen::Index cols() const { return cols_; }
  /// Exactly the shape (r, c) (c < 0: any number of columns), else InputError naming the shape.
  const MatIn& require(Eigen::Index r, Eigen::Index c) const;

 private:
  nb::ndarray<nb::ro> array_;
  const double* data_ = nullptr;
  Eigen::Index rows_ = 0, cols_ = 0;
  const char *where_, *what_;
};

Vector3 vec3(nb::handle h, const char* where, const char* what, Values values = Values::Finite);
Matrix3 mat3(nb::handle h, const char* where, const char* what);
Eigen::VectorXd vecx(nb::handle h, const char* where, const char* what);
/// A quaternion given as (x, y, z, w), the order of Eigen's coefficients and of Pinocchio's
/// configuration vectors.
Quaternion quat_xyzw(nb::handle h, const char* where, const char* what, Values values = Values::Finite);
/// A Python number (int or float) as a double, else InputError naming the argument.
double number(nb::handle x, const char* where, const char* what);
/// The name of a Python object's type, for messages.
std::string py_type_name(nb::handle h);
/// A speed argument (approach_speed): finite and positive, the main job's bound on the key
/// approach-speed; else InputError "<where>: <what> must be positive (m/s), got <x>".
double speed_arg(double x, const char* where, const char* what);

/// A library message about flags ("--key: ..." or "--a/--b: ...") as the Python call's: when one of
/// the flags is a keyword argument of the call (an underscore for a dash), "<where>: key: ..." with
/// the keys as keywords; any other message unchanged.
std::string keyword_message(const std::string& message, const std::string& where,
                            const std::vector<std::string>& keywords);
/// Calls `f()`; an InputError (a JointRateLimitError stays one) leaves with keyword_message's text.
template <class F>
decltype(auto) with_keyword_errors(const std::string& where, const std::vector<std::string>& keywords,
                                   F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const JointRateLimitError& e) {
    throw JointRateLimitError(keyword_message(e.what(), where, keywords));
  } catch (const InputError& e) {
    throw InputError(keyword_message(e.what(), where, keywords));
  }
}

namespace keyword_detail {
template <class A>
auto keyword_name(std::vector<std::string>& names, const A& a, int) -> decltype((void)a.name_, void()) {
  if (a.name_) names.emplace_back(a.name_);
}
template <class A>
void keyword_name(std::vector<std::string>&, const A&, long) {}

template <class Fn, class R, class... A>
auto with_keyword_errors_fn(std::string where, std::vector<std::string> keywords, Fn fn,
                            R (Fn::*)(A...) const) {
  return [where = std::move(where), keywords = std::move(keywords), fn = std::move(fn)](A... a) -> R {
    return with_keyword_errors(where, keywords, [&]() -> R { return fn(std::forward<A>(a)...); });
  };
}
}  // namespace keyword_detail

/// `fn` (a lambda bound with the nanobind `extra`: its "name"_a arguments) whose InputError names
/// the call's keyword arguments as keywords (keyword_message), not as the command's flags.
template <class Fn, class... Extra>
auto keyword_errors(const std::string& where, Fn fn, const Extra&... extra) {
  std::vector<std::string> keywords;
  (keyword_detail::keyword_name(keywords, extra, 0), ...);
  return keyword_detail::with_keyword_errors_fn(where, std::move(keywords), std::move(fn), &Fn::operator());
}

/// The frame argument of the algorithms: None (the model's end-effector), an index or a frame name.
int frame_arg(const Model& model, nb::handle frame, const char* where);
/// InputError unless `data` was made from a model of the same size as `model`.
void check_data(const Model& model, const Data& data, const char* where);
/// The joint model of the contact ("free", "locked", "armature") with the armature per coordinate
/// (None: zeros; one number for every joint; or one per joint), as the scenario keys contact-joints and
/// armature; `where` names the call in messages.
ContactJoints joints_arg(const Model& model, const std::string& joints, nb::handle armature,
                         const char* where);
/// The paper's target (Target's defaults) for the calls that are given none.
const Target& target_or_default(const Target* t);

}  // namespace ffsr::python
