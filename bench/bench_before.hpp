// bench/bench_before.hpp -- the CRBA and the M_ie paths as they were before the allocation-free
// fixed-size rewrite (ffsr 0.1.0 at commit 5e16f05), frozen here so that ffsr-bench-pinocchio times
// the current code, this code and Pinocchio in one run: a regression shows at every size.
#pragma once

#include "ffsr/model/model.hpp"

#include <cmath>
#include <vector>

// Copied from include/ffsr/algorithm/{kinematics,crba,effective_mass,articulated_effective_mass}.hpp
// and spatial/spatial.hpp of that commit, with their own workspace (BeforeData) so that later changes
// of ffsr::Data cannot change them. The argument checks are kept (they are part of the old cost).

namespace ffsr_bench::before {

using namespace ffsr;

/// spatial.hpp's SpatialInertia of that commit (m, h = m c, Ibar about the reference point).
struct SpatialInertia {
  double m = 0.0;
  Vector3 h = Vector3::Zero();
  Matrix3 Ibar = Matrix3::Zero();
  static SpatialInertia from_com(double mass, const Vector3& c, const Matrix3& I_com) {
    SpatialInertia s;
    s.m = mass;
    s.h = mass * c;
    s.Ibar = I_com + mass * (c.squaredNorm() * Matrix3::Identity() - c * c.transpose());
    return s;
  }
  Vector6 operator*(const Vector6& V) const {
    Vector6 f;
    f.head<3>() = m * V.head<3>() - h.cross(V.tail<3>());
    f.tail<3>() = h.cross(V.head<3>()) + Ibar * V.tail<3>();
    return f;
  }
  SpatialInertia& operator+=(const SpatialInertia& o) {
    m += o.m;
    h += o.h;
    Ibar += o.Ibar;
    return *this;
  }
  Matrix6 matrix() const {
    Matrix6 M;
    M << m * Matrix3::Identity(), -skew(h), skew(h), Ibar;
    return M;
  }
};

/// The fields of ffsr::Data those functions wrote.
struct BeforeData {
  explicit BeforeData(const Model& model)
      : R(static_cast<size_t>(model.nb())),
        p(static_cast<size_t>(model.nb())),
        S(6, model.nb() - 1),
        Ic(static_cast<size_t>(model.nb())),
        H(model.nv(), model.nv()),
        L(model.nv(), model.nv()),
        w(model.nv()),
        y(model.nv()),
        A(static_cast<size_t>(model.nb())),
        IA(static_cast<size_t>(model.nb())),
        pA(static_cast<size_t>(model.nb())),
        U(static_cast<size_t>(model.nb())),
        D(model.n()),
        u(model.n()),
        path(static_cast<size_t>(model.nb())) {
    S.setZero();
    H.setZero();
    L.setZero();
  }
  std::vector<Matrix3> R;
  std::vector<Vector3> p;
  BasePose base;
  Eigen::Matrix<double, 6, Eigen::Dynamic> S;
  std::vector<SpatialInertia> Ic;
  Eigen::MatrixXd H, L;
  Eigen::VectorXd w, y;
  std::vector<Vector6> A;
  std::vector<Matrix6> IA;
  std::vector<Vector6> pA, U;
  Eigen::VectorXd D, u;
  std::vector<int> path;
};

inline void check_configuration(const Model& model, const BasePose& base,
                                const Eigen::Ref<const Eigen::VectorXd>& theta, const char* where) {
  detail::require_size(theta.size(), model.n(), where, "theta");
  detail::require_finite_all(theta, where, "theta");
  detail::require_finite_all(base.position, where, "base position");
  detail::require_finite_all(base.orientation.coeffs(), where, "base orientation");
  const double qn = base.orientation.norm();
  if (qn < 1e-9) throw InputError(detail::str(where, ": base orientation quaternion has zero norm"));
}

inline int coordinate_axis(const Vector3& axis) {
  if (axis.y() == 0.0 && axis.z() == 0.0) return 0;
  if (axis.x() == 0.0 && axis.z() == 0.0) return 1;
  if (axis.x() == 0.0 && axis.y() == 0.0) return 2;
  return -1;
}

inline void forward_kinematics(const Model& model, BeforeData& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta) {
  check_configuration(model, base, theta, "forward_kinematics");
  data.base.position = base.position;
  data.base.orientation = base.orientation.normalized();
  data.R[0] = data.base.orientation.toRotationMatrix();
  data.p[0] = base.position;
  const int nb = model.nb();
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    const auto ui = static_cast<size_t>(i);
    const auto pi = static_cast<size_t>(b.parent);
    const Matrix3 Rj = data.R[pi].lazyProduct(b.tree.R);
    const Vector3 pj = data.p[pi] + data.R[pi] * b.tree.p;
    const Vector3 z = Rj * b.joint.axis;
    const double q = b.joint_position(theta), k = b.multiplier;
    if (b.joint.type == JointType::Revolute) {
      const int a = coordinate_axis(b.joint.axis);
      if (a >= 0) {
        double s, c;
        detail::sin_cos(q, s, c);
        s *= b.joint.axis(a);
        const int c1 = (a + 1) % 3, c2 = (a + 2) % 3;
        Matrix3& R = data.R[ui];
        R.col(a) = Rj.col(a);
        R.col(c1) = c * Rj.col(c1) + s * Rj.col(c2);
        R.col(c2) = c * Rj.col(c2) - s * Rj.col(c1);
      } else {
        data.R[ui].noalias() = Rj.lazyProduct(rotation_about(b.joint.axis, q));
      }
      data.p[ui] = pj;
      data.S.col(i - 1) << k * (pj - data.p[0]).cross(z), k * z;
    } else {
      data.R[ui] = Rj;
      data.p[ui] = pj + z * q;
      data.S.col(i - 1) << k * z, Vector3::Zero();
    }
  }
}

inline Vector3 frame_position(const Model& model, const BeforeData& data, int frame) {
  const Frame& f = model.frame(frame);
  const auto b = static_cast<size_t>(f.body);
  return data.p[b] + data.R[b] * f.pose.p;
}

inline const Eigen::MatrixXd& crba(const Model& model, BeforeData& data, const BasePose& base,
                                   const Eigen::Ref<const Eigen::VectorXd>& theta) {
  forward_kinematics(model, data, base, theta);
  const int nb = model.nb();
  const Vector3& p0 = data.p[0];
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    const Matrix3& Ri = data.R[ui];
    data.Ic[ui] =
        SpatialInertia::from_com(in.mass, data.p[ui] + Ri * in.com - p0, Ri * in.I * Ri.transpose());
  }
  for (int i = nb - 1; i > 0; --i)
    data.Ic[static_cast<size_t>(model.body(i).parent)] += data.Ic[static_cast<size_t>(i)];
  Eigen::MatrixXd& H = data.H;
  H.setZero();
  H.topLeftCorner<6, 6>() = data.Ic[0].matrix();
  for (int i = 1; i < nb; ++i) {
    const Vector6 S = data.S.col(i - 1);
    const Vector6 F = data.Ic[static_cast<size_t>(i)] * S;
    const int ci = 6 + model.body(i).coord;
    H(ci, ci) += S.dot(F);
    for (int j = model.body(i).parent; j > 0; j = model.body(j).parent) {
      const int cj = 6 + model.body(j).coord;
      const double hij = data.S.col(j - 1).dot(F);
      H(cj, ci) += hij;
      H(ci, cj) += hij;
    }
    H.block<6, 1>(0, ci) += F;
    H.block<1, 6>(ci, 0) += F.transpose();
  }
  if (!std::isfinite(H.sum())) throw NumericalError("crba: the inertia matrix H is not finite");
  return H;
}

inline void cholesky(const Eigen::MatrixXd& A, Eigen::MatrixXd& L) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    double d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > 0.0)) throw NumericalError("effective_mass: the inertia matrix is not positive definite");
    const double ljj = std::sqrt(d);
    L(j, j) = ljj;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double s = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / ljj;
    }
  }
}

inline void cholesky_forward(const Eigen::MatrixXd& L, Eigen::VectorXd& x) {
  const Eigen::Index n = L.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    double s = x(i);
    for (Eigen::Index k = 0; k < i; ++k) s -= L(i, k) * x(k);
    x(i) = s / L(i, i);
  }
}

inline void check_unit_direction(const Vector3& u, const char* where) {
  detail::require_finite_all(u, where, "direction u");
  if (std::abs(u.norm() - 1.0) > 1e-9) throw InputError(detail::str(where, ": direction u must be a unit vector"));
}

inline void jacobian_transpose_times(const Model& model, BeforeData& data, int frame, const Vector3& f,
                                     const Vector3& m) {
  const Vector3 pe = frame_position(model, data, frame);
  if (!pe.allFinite()) throw NumericalError("effective_mass: the frame position overflows");
  data.w.setZero();
  data.w.head<3>() = f;
  data.w.segment<3>(3) = (pe - data.p[0]).cross(f) + m;
  for (int i = model.frame(frame).body; i > 0; i = model.body(i).parent) {
    const auto S = data.S.col(i - 1);
    data.w(6 + model.body(i).coord) +=
        model.body(i).joint.type == JointType::Revolute
            ? S.tail<3>().dot((pe - data.p[static_cast<size_t>(i)]).cross(f)) + S.tail<3>().dot(m)
            : S.head<3>().dot(f);
  }
}

/// inverse_effective_mass (dense: crba's H, Cholesky, one forward substitution).
inline double inverse_effective_mass(const Model& model, BeforeData& data, int frame, const Vector3& u) {
  check_unit_direction(u, "effective_mass");
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    throw InputError("effective_mass: frame index out of range");
  jacobian_transpose_times(model, data, frame, u, Vector3::Zero());
  cholesky(data.H, data.L);
  data.y = data.w;
  cholesky_forward(data.L, data.y);
  return data.y.squaredNorm();
}

inline bool solve_spd6(const Matrix6& A, const Vector6& b, Vector6& x) {
  double L[6][6];
  for (int j = 0; j < 6; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;
    const double ljj = std::sqrt(d), inv = 1.0 / ljj;
    L[j][j] = ljj;
    for (int i = j + 1; i < 6; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s * inv;
    }
  }
  for (int i = 0; i < 6; ++i) {
    double s = b(i);
    for (int k = 0; k < i; ++k) s -= L[i][k] * x(k);
    x(i) = s / L[i][i];
  }
  for (int i = 5; i >= 0; --i) {
    double s = x(i);
    for (int k = i + 1; k < 6; ++k) s -= L[k][i] * x(k);
    x(i) = s / L[i][i];
  }
  return true;
}

/// inverse_effective_mass_articulated (the articulated-body recursion with 6x6 matrices).
inline double inverse_effective_mass_articulated(const Model& model, BeforeData& data, int frame,
                                                 const Vector3& u) {
  check_unit_direction(u, "effective_mass");
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    throw InputError("effective_mass: frame index out of range");
  const Vector3 pe = frame_position(model, data, frame);
  if (!pe.allFinite()) throw NumericalError("effective_mass: the frame position overflows");
  const int nb = model.nb();
  if (nb - 1 != model.n()) throw InputError("inverse_effective_mass_articulated: the model has mimic joints");
  const int ee = model.frame(frame).body;
  const Vector3& p0 = data.p[0];
  Vector6 f;
  f << u, (pe - p0).cross(u);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    const Matrix3& Ri = data.R[ui];
    data.IA[ui] =
        SpatialInertia::from_com(in.mass, data.p[ui] + Ri * in.com - p0, Ri * in.I * Ri.transpose()).matrix();
    data.pA[ui].setZero();
  }
  data.pA[static_cast<size_t>(ee)] = -f;
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const auto up = static_cast<size_t>(model.body(i).parent);
    const Vector6 S = data.S.col(i - 1);
    Vector6& U = data.U[ui];
    U.noalias() = data.IA[ui] * S;
    const double D = S.dot(U);
    if (!(D > 0.0)) throw NumericalError("effective_mass: the articulated inertia is not positive definite");
    data.D(i - 1) = D;
    const double ui_ = -S.dot(data.pA[ui]);
    data.u(i - 1) = ui_;
    data.IA[up].noalias() += data.IA[ui] - U * (U.transpose() / D);
    data.pA[up].noalias() += data.pA[ui] + U * (ui_ / D);
  }
  if (!solve_spd6(data.IA[0], -data.pA[0], data.A[0]))
    throw NumericalError("effective_mass: the articulated inertia of the base is not positive definite");
  int len = 0;
  for (int i = ee; i > 0; i = model.body(i).parent) data.path[static_cast<size_t>(len++)] = i;
  for (int k = len - 1; k >= 0; --k) {
    const int i = data.path[static_cast<size_t>(k)];
    const auto ui = static_cast<size_t>(i);
    const Vector6& ap = data.A[static_cast<size_t>(model.body(i).parent)];
    const double qdd = (data.u(i - 1) - data.U[ui].dot(ap)) / data.D(i - 1);
    data.A[ui] = ap + data.S.col(i - 1) * qdd;
  }
  return f.dot(data.A[static_cast<size_t>(ee)]);
}

/// integrated_effective_mass, frozen: dense below 8 joints (and with mimics), the recursion from there.
inline double integrated_effective_mass(const Model& model, BeforeData& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Vector3& u, double target_inverse_mass) {
  if (model.n() < 8 || model.nb() - 1 != model.n()) {
    crba(model, data, base, theta);
    return 1.0 / (inverse_effective_mass(model, data, frame, u) + target_inverse_mass);
  }
  forward_kinematics(model, data, base, theta);
  return 1.0 / (inverse_effective_mass_articulated(model, data, frame, u) + target_inverse_mass);
}

}  // namespace ffsr_bench::before
