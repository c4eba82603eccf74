// ffsr/simulate/multibody.hpp -- the full robot-plus-target contact simulation (Figure 2), the
// "classical numerical integration method" that the paper uses as its reference (Tables 3 and 6).
#pragma once

#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/algorithm/forward_dynamics.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/simulate/cvode.hpp"

#include <string>
#include <vector>

// The free-floating robot (joints passive: zero torque, unless MultibodyContactOptions gives a joint PD
// servo holding the pre-contact rates and an armature; gravity model.gravity, zero by default) and
// the target (a free rigid body) touch at one point. The target's surface near the contact is the
// plane through its material contact point (r_tp) with normal u_n, both fixed in the target; the
// end-effector is a point: the origin of the end-effector frame, or a point fixed in the end-effector
// at rho from it (MultibodyContactOptions::robot_contact_offset: a contact elsewhere on the gripper).
// The deformation is that point's penetration of the plane, delta = u . (p_c - p_tp) with
// u = R_t u_n, and the law of contact/contact_law.hpp gives the force F(delta, delta_dot) >= 0. It
// acts along u: +F u on the target and -F u on the robot, both at the robot's contact point p_c, so
// the pair is collinear and the total linear and angular momentum of robot plus target are conserved
// exactly (a test checks it).
//
// Start: first touch (delta = 0). The robot moves with zero total momentum and the velocity of its
// contact point equal to `approach_speed` along u (joint rates from the pseudo-inverse of the linear
// rows of J_f at that point; the base follows from momentum conservation); the target moves with its
// own velocity and spin. delta_dot^- = u . (v_e - v_tp) of that state (Eq. 10-12) sets the damping (Eq. 22).
// Integration: SUNDIALS CVODE (BDF, Newton, dense), tight tolerances, on displacements from the
// initial state so that the ~0.1 mm deformation is resolved; separation (delta back to zero) and the
// force peak (dF/dt = 0) are located by CVODE's root finding.

namespace ffsr {

struct MultibodyContactOptions {
  double rtol = 1e-10;           ///< CVODE relative tolerance
  double atol_position = 1e-15;  ///< m and rad (the states are displacements from the start)
  double atol_velocity = 1e-13;  ///< m/s and rad/s
  long max_num_steps = 200000;   ///< CVODE step budget
  double max_duration = 0;       ///< give up after this contact time (s); 0: 100 x the Hertz estimate
  bool record_series = false;    ///< keep (t, F, delta) at every internal step
  /// rho: the robot's contact point is the end-effector frame's origin plus rho (inertial frame at
  /// the first touch; the point is fixed in the end-effector body). Zero: the origin itself.
  Vector3 robot_contact_offset = Vector3::Zero();
  /// Servoed joints (empty: zero for every joint; else size n): a PD on each joint holding the
  /// pre-contact rates theta_dot_0, tau_k = -K_k (theta_k - theta_0k - theta_dot_0k t) - D_k
  /// (theta_dot_k - theta_dot_0k), N m/rad and N m s/rad (N/m, N s/m prismatic), and the reflected
  /// rotor inertia a_k added to H's joint diagonal (algorithm/joint_models.hpp), kg m^2 (kg).
  /// All zero: the passive free joints of the paper.
  Eigen::VectorXd joint_stiffness, joint_damping, armature;
};

struct ContactSample {
  double t = 0, force = 0, delta = 0;
};

/// Robot and target at one instant of the contact run (inertial frame): what a phase after it starts from.
struct ContactBodies {
  BasePose base;             ///< the robot's base pose
  Eigen::VectorXd theta, v;  ///< joint angles (rad) and generalized velocity [v_0; w_0; theta_dot]
  Target target;             ///< the target's pose, velocity and spin (its other fields as given)
};

struct MultibodyContactResult {
  std::string model;                     ///< contact law name
  double approach_velocity = 0;          ///< delta_dot^- (m/s)
  double integrated_effective_mass = 0;  ///< M_ie at the first touch (kg), Eq. 14
  double f_max = 0;                      ///< peak contact force (N)
  double t_at_f_max = 0;                 ///< time of the peak from first touch (s)
  double delta_at_f_max = 0;             ///< deformation at the peak (m)
  double delta_max = 0;                  ///< largest deformation (m)
  double contact_duration = 0;           ///< time to separation (s)
  double separation_velocity = 0;        ///< delta_dot at separation (m/s, negative)
  double restitution = 0;                ///< realized coefficient: -separation_velocity / approach_velocity
  Vector6 momentum_start = Vector6::Zero();       ///< [P; L about o] of robot + target at first touch
  Vector6 momentum_end = Vector6::Zero();         ///< the same at separation
  double energy_start = 0;                        ///< kinetic energy of robot + target at first touch (J)
  double energy_end = 0;                          ///< the same at separation (equal for c_r = 1)
  long steps = 0;                                 ///< CVODE internal steps
  std::vector<ContactSample> series;              ///< when requested
  Vector6 base_velocity_start = Vector6::Zero();  ///< robot base [v_0; w_0] at first touch (inertial)
  Vector6 base_velocity_end = Vector6::Zero();    ///< the same at separation
  ContactBodies start, end;  ///< robot and target at the first touch and at the separation (delta = 0)
};

namespace detail {

/// Rate of a rotation vector phi (R = exp([phi]) R_0) for the angular velocity w in o:
/// phi_dot = J_l(phi)^-1 w.
inline Vector3 rotation_vector_rate(const Vector3& phi, const Vector3& w) {
  const double th2 = phi.squaredNorm();
  double c;  // (1 - (th/2) cot(th/2)) / th^2
  if (th2 < 1e-6) {
    c = 1.0 / 12.0 + th2 / 720.0;
  } else {
    const double th = std::sqrt(th2);
    c = (1.0 - 0.5 * th / std::tan(0.5 * th)) / th2;
  }
  return w - 0.5 * phi.cross(w) + c * phi.cross(phi.cross(w));
}

/// The state of the contact simulation: displacements from the first touch and velocities.
///  [dp0 (3), phi0 (3), dtheta (n), v0 (3), w0 (3), theta_dot (n), dp_t (3), phi_t (3), v_t (3), w_t (3)]
struct ContactSystem {
  const Model& model;
  Data data;
  BasePose base0;
  Eigen::VectorXd theta0;
  int frame;
  Target target;  ///< at the first touch
  Matrix3 Rt0;
  Vector3 ct0, r0;  ///< target centre of mass and contact offset (in o) at the first touch
  Vector3 rho_ee;   ///< the robot's contact point from the end-effector origin, end-effector frame
  int n;
  Eigen::VectorXd qd0, K, D,
      armature;  ///< joint servo and armature (MultibodyContactOptions; zeros if unset)
  // scratch
  Eigen::VectorXd theta, v, tau, a, ydot_scratch, y_scratch;

  /// `rho` is the robot's contact point from the end-effector origin, inertial frame at (b, th).
  ContactSystem(const Model& m, const BasePose& b, const Eigen::VectorXd& th, int f, const Target& t,
                const Vector3& rho = Vector3::Zero())
      : model(m),
        data(m),
        base0(b),
        theta0(th),
        frame(f),
        target(t),
        n(m.n()),
        qd0(Eigen::VectorXd::Zero(m.n())),
        K(Eigen::VectorXd::Zero(m.n())),
        D(Eigen::VectorXd::Zero(m.n())),
        armature(Eigen::VectorXd::Zero(m.n())),
        theta(m.n()),
        v(m.nv()),
        tau(m.nv()),
        a(m.nv()) {
    base0.orientation.normalize();
    Rt0 = target.rotation();
    ct0 = target.position;
    r0 = Rt0 * target.contact_offset;
    forward_kinematics(model, data, base0, theta0);
    rho_ee = frame_pose(model, data, frame).R.transpose() * rho;
  }
  Eigen::Index size() const { return 24 + 2 * n; }
  // offsets
  Eigen::Index iv() const { return 6 + n; }
  Eigen::Index it() const { return 12 + 2 * n; }

  struct Kin {
    BasePose base;
    Matrix3 Rt;
    Vector3 ct, u, pe, ve, ptp, vtp, wt, vt, rho;  ///< pe, ve: the robot's contact point; rho = pe - origin
    double delta, delta_dot;
  };
  /// Kinematics of the contact at state y (writes data kinematics and data.J).
  Kin kinematics(const Eigen::Ref<const Eigen::VectorXd>& y) {
    Kin k;
    k.base.position = base0.position + y.segment<3>(0);
    k.base.orientation =
        Quaternion(rotation_from_vector(y.segment<3>(3)) * base0.orientation.toRotationMatrix());
    theta = theta0 + y.segment(6, n);
    v = y.segment(iv(), 6 + n);
    forward_kinematics(model, data, k.base, theta);
    frame_jacobian(model, data, frame);
    const Pose pf = frame_pose(model, data, frame);
    k.rho = pf.R * rho_ee;
    k.pe = pf.p + k.rho;
    k.ve = data.J.topRows<3>() * v + (data.J.bottomRows<3>() * v).cross(k.rho);
    const Eigen::Index t0 = it();
    k.Rt = rotation_from_vector(y.segment<3>(t0 + 3)) * Rt0;
    k.ct = ct0 + y.segment<3>(t0);
    k.vt = y.segment<3>(t0 + 6);
    k.wt = y.segment<3>(t0 + 9);
    k.u = k.Rt * target.normal.normalized();
    k.ptp = k.ct + k.Rt * target.contact_offset;
    k.vtp = k.vt + k.wt.cross(k.ptp - k.ct);
    const Vector3 d = k.pe - k.ptp;
    k.delta = k.u.dot(d);
    k.delta_dot = k.wt.cross(k.u).dot(d) + k.u.dot(k.ve - k.vtp);
    return k;
  }

  template <class Law>
  double force(const Law& law, const Kin& k) const {
    return law.force(k.delta, k.delta_dot);
  }

  /// The servo's joint torques at time t (from the first touch) added to tau's joint entries.
  void add_joint_servo(double t, const Eigen::Ref<const Eigen::VectorXd>& y) {
    tau.tail(n).array() -=
        K.array() * (y.segment(6, n) - qd0 * t).array() + D.array() * (y.segment(iv() + 6, n) - qd0).array();
  }

  /// a = (H + diag(0, armature))^-1 (tau - C): forward_dynamics with the armature on H's joint diagonal.
  void dynamics(const BasePose& base) {
    if (armature.isZero()) {
      forward_dynamics(model, data, base, theta, v, tau, a);
      return;
    }
    crba(model, data, base, theta);
    a = tau - bias_forces(model, data, base, theta, v);
    detail::factor_with_armature(data, armature, "simulate_contact");
    detail::cholesky_solve(data.L, a);
  }

  template <class Law>
  void rhs(const Law& law, double t, const Eigen::Ref<const Eigen::VectorXd>& y,
           Eigen::Ref<Eigen::VectorXd> ydot) {
    const Kin k = kinematics(y);
    const double F = law.force(k.delta, k.delta_dot);
    // robot: H a = J^T [-F u; rho x (-F u)] - C + [0; servo torques]
    tau.noalias() = data.J.topRows<3>().transpose() * (-F * k.u);
    tau.noalias() += data.J.bottomRows<3>().transpose() * k.rho.cross(-F * k.u);
    add_joint_servo(t, y);
    dynamics(k.base);
    ydot.segment<3>(0) = v.head<3>();
    ydot.segment<3>(3) = rotation_vector_rate(y.segment<3>(3), v.segment<3>(3));
    ydot.segment(6, n) = v.tail(n);
    ydot.segment(iv(), 6 + n) = a;
    // target: m v_dot = F u; I w_dot = (p_e - c) x F u - w x I w
    const Eigen::Index t0 = it();
    const Matrix3 I = k.Rt * target.inertia * k.Rt.transpose();
    const Vector3 f = F * k.u;
    ydot.segment<3>(t0) = k.vt;
    ydot.segment<3>(t0 + 3) = rotation_vector_rate(y.segment<3>(t0 + 3), k.wt);
    ydot.segment<3>(t0 + 6) = f / target.mass + model.gravity;
    ydot.segment<3>(t0 + 9) = I.ldlt().solve((k.pe - k.ct).cross(f) - k.wt.cross(I * k.wt));
  }

  /// Robot and target at state y: the displacements added to the first touch's poses.
  ContactBodies bodies(const Eigen::Ref<const Eigen::VectorXd>& y) const {
    ContactBodies s;
    s.base.position = base0.position + y.segment<3>(0);
    s.base.orientation =
        Quaternion(rotation_from_vector(y.segment<3>(3)) * base0.orientation.toRotationMatrix());
    s.theta = theta0 + y.segment(6, n);
    s.v = y.segment(iv(), 6 + n);
    const Eigen::Index t0 = it();
    const Matrix3 Rt = rotation_from_vector(y.segment<3>(t0 + 3)) * Rt0;
    s.target = target;
    s.target.position = ct0 + y.segment<3>(t0);
    s.target.attitude = Quaternion(Rt);
    s.target.velocity = y.segment<3>(t0 + 6);
    s.target.angular_velocity = Rt.transpose() * y.segment<3>(t0 + 9);
    return s;
  }

  /// Kinetic energy of robot + target (bodies summed).
  double total_energy(const Eigen::Ref<const Eigen::VectorXd>& y) {
    const Kin k = kinematics(y);
    const Matrix3 I = k.Rt * target.inertia * k.Rt.transpose();
    return kinetic_energy(model, data, v) + 0.5 * v.tail(n).dot(armature.cwiseProduct(v.tail(n))) +
           0.5 * target.mass * k.vt.squaredNorm() + 0.5 * k.wt.dot(I * k.wt);
  }

  /// Total momentum of robot + target, [P; L about o].
  Vector6 total_momentum(const Eigen::Ref<const Eigen::VectorXd>& y) {
    const Kin k = kinematics(y);
    Vector6 h = momentum(model, data, v);  // about the base origin
    Vector6 out;
    out.head<3>() = h.head<3>();
    out.tail<3>() = h.tail<3>() + k.base.position.cross(h.head<3>());
    const Matrix3 I = k.Rt * target.inertia * k.Rt.transpose();
    out.head<3>() += target.mass * k.vt;
    out.tail<3>() += k.ct.cross(target.mass * k.vt) + I * k.wt;
    return out;
  }
};

}  // namespace detail

/// Initial joint rates of the approach: the end-effector's point at `rho` from its origin (inertial
/// frame) moves at `approach_speed` along u with zero total momentum,
/// theta_dot = pinv(J_f,v - [rho]x J_f,w) (approach_speed u) (complete orthogonal decomposition, so
/// a rank-deficient J_f such as the planar robot's works). Runs crba.
inline Eigen::VectorXd approach_joint_rates(const Model& model, Data& data, const BasePose& base,
                                            const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                            const Vector3& u, double approach_speed,
                                            const Vector3& rho = Vector3::Zero()) {
  generalized_jacobian(model, data, base, theta, frame);
  Eigen::MatrixXd Jv = data.Jf.topRows<3>();
  if (!rho.isZero()) Jv -= skew(rho) * data.Jf.bottomRows<3>();
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(Jv);
  cod.setThreshold(1e-10);
  return cod.solve(Vector3(approach_speed * u));
}

namespace detail {

/// The contact force of a law chosen at run time. One instantiation for all laws: the simulation
/// needs only F(delta, delta_dot), and a visit per force evaluation costs nothing beside the
/// dynamics (templating the whole run on the law would compile it eight times).
struct AnyLawForce {
  const AnyContactLaw& any;
  double force(double d, double dd) const { return ffsr::force(any, d, dd); }
};

/// The robot's approach at the first touch: the integrated effective mass along u (Eq. 14, with
/// the contact point at rho from the end-effector origin), the joint rates and base velocity.
struct ApproachState {
  double M_ie;
  Eigen::VectorXd qd;
  Vector6 xb;
};

/// Places `target` so that its contact point touches the robot's contact point (writes
/// target.position) and returns the approach state: M_ie = 1 / (s^T M^-1 s + target's inverse mass
/// along u), s = [u; rho x u]; theta_dot from approach_joint_rates; the base velocity from zero total
/// momentum. Runs crba. Writes data.
inline ApproachState approach_at_first_touch(const Model& model, Data& data, const BasePose& base,
                                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                             Target& target, double approach_speed, const Vector3& rho) {
  crba(model, data, base, theta);
  const Vector3 pe = frame_pose(model, data, frame).p + rho;
  const Vector3 u = target.normal_world();
  target.position = pe - target.offset_world();
  double inv_me;
  if (rho.isZero()) {
    inv_me = inverse_effective_mass(model, data, frame, u);
  } else {
    Vector6 s;
    s << u, rho.cross(u);
    inv_me = s.dot(inverse_inertia_matrix(model, data, frame) * s);
  }
  const double M_ie = 1.0 / (inv_me + target.inverse_mass_along_normal());
  const Eigen::VectorXd qd = approach_joint_rates(model, data, base, theta, frame, u, approach_speed, rho);
  const Vector6 xb = base_velocity_from_momentum(model, data, qd);
  return {M_ie, qd, xb};
}

/// The state vector of `sys` at the first touch: zero displacements, the robot's base velocity
/// `xb` and joint rates `qd`, the target's velocity and spin.
inline Eigen::VectorXd contact_initial_state(const ContactSystem& sys, const ApproachState& start,
                                             const Target& target) {
  Eigen::VectorXd y0 = Eigen::VectorXd::Zero(sys.size());
  y0.segment<6>(sys.iv()) = start.xb;
  y0.segment(sys.iv() + 6, sys.n) = start.qd;
  y0.segment<3>(sys.it() + 6) = target.velocity;
  y0.segment<3>(sys.it() + 9) = target.angular_velocity_world();
  return y0;
}

/// Hertz time scale of the contact, (M/K)^(1/(alpha+1)) v^((1-alpha)/(alpha+1)): a contact lasts
/// a few of it.
inline double hertz_time(const ContactParams& params, double M_ie, double vin) {
  const double a1 = params.alpha + 1;
  return std::pow(M_ie / params.K, 1.0 / a1) * std::pow(vin, (1.0 - params.alpha) / a1);
}

/// CVODE settings of the contact simulation: position tolerances on the displacements (robot and
/// target), velocity tolerances on the rest, steps bounded by fractions of the Hertz time.
inline cvode::Options contact_cvode_options(const MultibodyContactOptions& options, const ContactSystem& sys,
                                            double t_hertz) {
  cvode::Options co;
  co.rtol = options.rtol;
  co.max_num_steps = options.max_num_steps;
  co.atol_vector = Eigen::VectorXd::Constant(sys.size(), options.atol_velocity);
  co.atol_vector.segment(0, 6 + sys.n).setConstant(options.atol_position);
  co.atol_vector.segment<6>(sys.it()).setConstant(options.atol_position);
  co.initial_step = 1e-3 * t_hertz;
  co.max_step = 0.05 * t_hertz;
  return co;
}

/// The root functions of the contact simulation at state y. Root 0: delta (separation,
/// decreasing); root 1: dF/dt (peak, decreasing), by a central difference of F with step h along
/// the exact state derivative. The peak root is armed only in compression with a positive force,
/// where the peak lies (at delta_dot = 0, dF/dt = lambda delta^alpha delta_ddot < 0): in restitution
/// a strongly damped contact hovers at the clamp, where dF/dt vanishes on an interval, which CVODE's
/// root finder must not see. `yd`, `yp` are scratch of the state's size.
template <class Law>
void contact_roots(ContactSystem& sys, const Law& law, double h, double t,
                   const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g,
                   Eigen::VectorXd& yd, Eigen::VectorXd& yp) {
  const auto k = sys.kinematics(y);
  g(0) = k.delta;
  if (!(sys.force(law, k) > 0.0) || !(k.delta_dot > 0.0)) {
    g(1) = -1.0;
    return;
  }
  sys.rhs(law, t, y, yd);
  yp = y + h * yd;
  const double Fp = sys.force(law, sys.kinematics(yp));
  yp = y - h * yd;
  const double Fm = sys.force(law, sys.kinematics(yp));
  g(1) = (Fp - Fm) / (2 * h);
}

/// The servo's per-joint values (MultibodyContactOptions): empty gives zeros; otherwise size n,
/// finite and >= 0. InputError "simulate_contact: <what> ...".
inline Eigen::VectorXd servo_values(const Eigen::VectorXd& v, const Model& model, const char* what) {
  if (v.size() == 0) return Eigen::VectorXd::Zero(model.n());
  require_size(v.size(), model.n(), "simulate_contact", what);
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (!(v(k) >= 0) || !std::isfinite(v(k)))
      throw InputError(str("simulate_contact: ", what, " of joint '", model.joint(int(k)).name,
                           "' must be finite and >= 0, got ", v(k)));
  return v;
}

/// Updates the running maxima of `res` (delta_max, f_max and where it occurred) with the sample
/// (t, F, delta) and appends it to the series when `record_series`.
inline void record_contact_sample(MultibodyContactResult& res, double t, double F, double delta,
                                  bool record_series) {
  res.delta_max = std::max(res.delta_max, delta);
  if (F > res.f_max) {
    res.f_max = F;
    res.t_at_f_max = t;
    res.delta_at_f_max = delta;
  }
  if (record_series) res.series.push_back({t, F, delta});
}

/// Writes the separation into `res`: the time, delta_dot (and restitution against `vin`), the
/// momentum and energy of the state `y`, the number of CVODE steps, the robot's base velocity, the
/// bodies' state.
inline void record_separation(MultibodyContactResult& res, ContactSystem& sys, const cvode::Integrator& integ,
                              double delta_dot, double vin) {
  res.contact_duration = integ.t();
  res.separation_velocity = delta_dot;
  res.restitution = -delta_dot / vin;
  res.momentum_end = sys.total_momentum(integ.y());
  res.energy_end = sys.total_energy(integ.y());
  res.steps = integ.num_steps();
  res.base_velocity_end = integ.y().segment<6>(sys.iv());
  res.end = sys.bodies(integ.y());
}

}  // namespace detail

/// The full multibody contact simulation (see the notes after the includes). `theta` is the capture
/// configuration; the target is placed so that its contact point touches the end-effector
/// (its `position` is ignored). Throws InputError for bad arguments or receding bodies,
/// IntegrationError for a CVODE failure, NumericalError if the bodies do not separate.
/// The steps: detail::approach_at_first_touch, contact_initial_state, contact_cvode_options,
/// the right-hand side ContactSystem::rhs with contact_roots, then record_contact_sample at each
/// step until the separation root (record_separation).
inline MultibodyContactResult simulate_contact(const Model& model, const BasePose& base,
                                               const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                               Target target, double approach_speed,
                                               const ContactParams& params, std::string_view law_name,
                                               const MultibodyContactOptions& options = {}) {
  using detail::str;
  target.validate("simulate_contact: target");
  validate(params, "simulate_contact");
  detail::require_finite(approach_speed, "simulate_contact", "approach speed");
  Data data(model);
  const Vector3& rho = options.robot_contact_offset;
  detail::require_finite_all(rho, "simulate_contact", "robot contact offset");
  const detail::ApproachState start =
      detail::approach_at_first_touch(model, data, base, theta, frame, target, approach_speed, rho);

  detail::ContactSystem sys(model, base, Eigen::VectorXd(theta), frame, target, rho);
  const Eigen::VectorXd y0 = detail::contact_initial_state(sys, start, target);
  const double vin = sys.kinematics(y0).delta_dot;
  if (!(vin > 0))
    throw InputError(str("simulate_contact: the bodies do not approach (delta_dot^- = ", vin,
                         " m/s); increase the approach speed"));
  const AnyContactLaw any_law = make_contact_law(law_name, params, vin);
  const detail::AnyLawForce law{any_law};
  MultibodyContactResult res;
  res.model = std::string(law_name);
  res.approach_velocity = vin;
  res.integrated_effective_mass = start.M_ie;
  const double t_hertz = detail::hertz_time(params, start.M_ie, vin);
  const double t_max = options.max_duration > 0 ? options.max_duration : 100.0 * t_hertz;

  sys.qd0 = start.qd;
  sys.K = detail::servo_values(options.joint_stiffness, model, "joint stiffness");
  sys.D = detail::servo_values(options.joint_damping, model, "joint damping");
  sys.armature = detail::servo_values(options.armature, model, "armature");
  auto rhs = [&](double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> yd) {
    sys.rhs(law, t, y, yd);
  };
  Eigen::VectorXd yd(sys.size()), yp(sys.size());
  auto roots = [&](double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) {
    detail::contact_roots(sys, law, 1e-6 * t_hertz, t, y, g, yd, yp);
  };
  cvode::Integrator integ(rhs, y0, 0.0, detail::contact_cvode_options(options, sys, t_hertz), 2, roots,
                          {-1, -1});
  res.momentum_start = sys.total_momentum(y0);
  res.energy_start = sys.total_energy(y0);
  res.base_velocity_start = y0.segment<6>(sys.iv());
  res.start = sys.bodies(y0);
  auto record = [&](double t, const Eigen::VectorXd& y) {
    const auto k = sys.kinematics(y);
    detail::record_contact_sample(res, t, sys.force(law, k), k.delta, options.record_series);
    return k;
  };
  record(0.0, y0);
  for (long guard = 0; guard <= options.max_num_steps; ++guard) {
    const auto status = integ.step(t_max);
    const auto k = record(integ.t(), integ.y());
    if (status == cvode::Integrator::Status::Root && integ.roots_found()[0] != 0 && integ.t() > 0) {
      detail::record_separation(res, sys, integ, k.delta_dot, vin);
      return res;
    }
    if (status == cvode::Integrator::Status::Reached) break;
  }
  throw NumericalError(str("simulate_contact: the bodies did not separate within ", t_max, " s"));
}

}  // namespace ffsr
