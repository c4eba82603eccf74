// fuzz/numeric_check.hpp -- the fuzz_numeric check: raw doubles (NaN, inf, zero, denormals, huge values)
// into the numeric entry points on the paper's robots. Each call returns finite numbers or throws an
// ffsr::Error.
#pragma once

#include "fuzz_checks.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <string>

// Input layout: one selector byte (entry point and robot), then the arguments as 8-byte doubles and a
// few bytes, in the order they are read below. Missing values take the paper's (Section 5.1 / 5.2).

namespace ffsr_fuzz {

/// The paper's robots, loaded once.
inline const ffsr::Model& paper_robot(bool seven) {
  static const ffsr::Model m3 = ffsr::model_from_urdf_file(FFSR_SOURCE_DIR "/robots/paper_3dof.urdf");
  static const ffsr::Model m7 = ffsr::model_from_urdf_file(FFSR_SOURCE_DIR "/robots/paper_7dof.urdf");
  return seven ? m7 : m3;
}

inline Eigen::VectorXd read_theta(Input& in, const ffsr::Model& model) {
  static const double paper3[] = {0.0, 150.0 * M_PI / 180, -100.0 * M_PI / 180};
  static const double paper7[] = {0, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2, 0};
  Eigen::VectorXd theta(model.n());
  for (int i = 0; i < model.n(); ++i)
    theta(i) = in.real(model.n() == 3 ? paper3[i] : model.n() == 7 ? paper7[i] : 0.0);
  return theta;
}

inline ffsr::BasePose read_base(Input& in) {
  ffsr::BasePose b;
  b.position = ffsr::Vector3(in.real(0), in.real(0), in.real(0));
  const double w = in.real(1), x = in.real(0), y = in.real(0), z = in.real(0);
  b.orientation = ffsr::Quaternion(w, x, y, z);
  return b;
}

inline ffsr::Target read_target(Input& in) {
  ffsr::Target t;
  t.mass = in.real(200);
  const double ixx = in.real(100), iyy = in.real(100), izz = in.real(100), ixy = in.real(0), ixz = in.real(0),
               iyz = in.real(0);
  t.inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  const double w = in.real(1), x = in.real(0), y = in.real(0), z = in.real(0);
  t.attitude = ffsr::Quaternion(w, x, y, z);
  t.contact_offset = ffsr::Vector3(in.real(-0.25), in.real(0.15), in.real(0));
  t.normal = ffsr::Vector3(in.real(1), in.real(0), in.real(0));
  return t;
}

inline void read_motion(Input& in, ffsr::Target& t) {
  t.position = ffsr::Vector3(in.real(2.75), in.real(1.45), in.real(0));
  t.velocity = ffsr::Vector3(in.real(0), in.real(0), in.real(0));
  t.angular_velocity = ffsr::Vector3(in.real(0), in.real(0), in.real(2.0 * M_PI / 180));
}

inline ffsr::ContactParams read_params(Input& in) {
  ffsr::ContactParams p;
  p.K = in.real(1e9);
  p.alpha = in.real(1.5);
  p.c_r = in.real(0.9);
  return p;
}

/// The law name: one of Table 1, or (rarely) an unknown one.
inline std::string read_law(Input& in) {
  const uint8_t b = in.byte(1);
  if (b == 255) return "no-such-law";
  const auto names = ffsr::contact_law_names();
  return std::string(names[b % names.size()]);
}

/// Is the target valid (validate throws InputError otherwise; anything else is a Finding)?
inline bool target_valid(const ffsr::Target& t) {
  return returns_or_ffsr_error("Target::validate", [&] { t.validate(); });
}

// --- 0: effective mass, Jacobians ----------------------------------------------------------------
inline void check_effective_mass(Input& in, const ffsr::Model& model) {
  const Eigen::VectorXd theta = read_theta(in, model);
  const ffsr::BasePose base = read_base(in);
  const ffsr::Target target = read_target(in);
  const int frame = static_cast<int>(in.byte(0) % (model.frames().size() + 1)) - 1;  // -1: the end-effector
  const int f = frame < 0 ? model.end_effector() : frame;
  ffsr::Data data(model);
  returns_or_ffsr_error("crba", [&] {
    ffsr::crba(model, data, base, theta);
    require_finite(data.H, "H");
  });
  returns_or_ffsr_error("generalized_jacobian", [&] {
    const Eigen::MatrixXd& Jf = ffsr::generalized_jacobian(model, data, base, theta, f);
    require_finite(data.J, "J_bm");
    require_finite(Jf, "J_f");
  });
  const ffsr::Vector3 u_raw(in.real(1), in.real(0), in.real(0));
  returns_or_ffsr_error("effective_mass(raw u)", [&] {
    const double m_e = ffsr::effective_mass(model, data, base, theta, f, u_raw);
    require_finite(m_e, "m_e");
    if (!(m_e > 0)) fail("m_e is not positive: " + std::to_string(m_e));
  });
  if (!target_valid(target)) return;  // integrated_effective_mass requires a validated target
  returns_or_ffsr_error("integrated_effective_mass", [&] {
    const double M_ie = ffsr::integrated_effective_mass(model, data, base, theta, f, target);
    require_finite(M_ie, "M_ie");
    if (!(M_ie > 0)) fail("M_ie is not positive: " + std::to_string(M_ie));
  });
  returns_or_ffsr_error("integrated_effective_mass_dense", [&] {
    const double M_ie = ffsr::integrated_effective_mass_dense(model, data, base, theta, f, target);
    require_finite(M_ie, "M_ie (dense)");
    if (!(M_ie > 0)) fail("M_ie (dense) is not positive: " + std::to_string(M_ie));
  });
  returns_or_ffsr_error("integrated_effective_mass(m_e, target)", [&] {
    const double M_ie = ffsr::integrated_effective_mass(in.real(5.8), target);
    require_finite(M_ie, "M_ie(m_e)");
  });
  returns_or_ffsr_error("integrated_effective_mass_gradient", [&] {
    Eigen::VectorXd grad(model.n());
    const double M_ie = ffsr::integrated_effective_mass_gradient_dense(
        model, data, base, theta, f, target.normal_world(), target.inverse_mass_along_normal(), grad);
    require_finite(M_ie, "M_ie (gradient)");
    require_finite(grad, "grad M_ie");
  });
}

// --- 1: the contact law --------------------------------------------------------------------------
inline void check_contact_law(Input& in) {
  const std::string name = read_law(in);
  const ffsr::ContactParams p = read_params(in);
  const double v0 = in.real(0.2052);
  const double M = in.real(5.8158);
  ffsr::AnyContactLaw law = ffsr::make_contact_law("hunt-crossley", {}, 1.0);
  if (!returns_or_ffsr_error("make_contact_law", [&] { law = ffsr::make_contact_law(name, p, v0); })) return;
  require_finite(ffsr::damping_factor(law), "f(c_r)");
  require_finite(ffsr::lambda(law), "lambda");
  returns_or_ffsr_error("zeta", [&] { require_finite(ffsr::zeta(law), "zeta"); });
  returns_or_ffsr_error("relative_error", [&] { require_finite(ffsr::relative_error(law), "xi"); });
  returns_or_ffsr_error("max_deformation",
                        [&] { require_finite(ffsr::max_deformation(law, M), "delta_max"); });
  returns_or_ffsr_error("max_force_estimate",
                        [&] { require_finite(ffsr::max_force_estimate(law, M), "F'_max"); });
  returns_or_ffsr_error("max_force_closed_form",
                        [&] { require_finite(ffsr::max_force_closed_form(law, M), "F_max"); });
  returns_or_ffsr_error("exact_peak", [&] {
    const ffsr::ForcePeak pk = ffsr::exact_peak(law, M);
    require_finite(pk.force, "exact F_max");
    require_finite(pk.deformation, "exact delta");
    require_finite(pk.deformation_rate, "exact delta_dot");
  });
  const double delta = in.real(1e-4), delta_dot = in.real(0.1);
  if (std::isfinite(delta) && std::isfinite(delta_dot)) {  // force() propagates NaN by contract
    returns_or_ffsr_error("force", [&] {
      const double F = ffsr::force(law, delta, delta_dot);
      if (std::isnan(F))
        fail("force(" + std::to_string(delta) + ", " + std::to_string(delta_dot) + ") is NaN");
      if (F < 0) fail("force is negative");
    });
  }
  returns_or_ffsr_error("deformation", [&] {
    std::visit([&](const auto& l) { require_finite(l.deformation(M, delta_dot), "delta(delta_dot)"); }, law);
  });
  returns_or_ffsr_error("model_accuracy", [&] {
    require_finite(ffsr::model_accuracy(in.real(1840), in.real(1851)), "accuracy");
  });
  returns_or_ffsr_error("approach_velocity", [&] {
    const ffsr::Vector3 u(in.real(1), in.real(0), in.real(0)), ve(in.real(0.2), in.real(0), in.real(0)),
        vt(in.real(0), in.real(0), in.real(0)), wt(in.real(0), in.real(0), in.real(0.03)),
        r(in.real(-0.25), in.real(0.15), in.real(0));
    require_finite(ffsr::approach_velocity(u, ve, vt, wt, r), "approach velocity");
  });
}

// --- 2: the multibody contact simulation (CVODE), with a small step budget ------------------------
inline void check_simulate_contact(Input& in, const ffsr::Model& model) {
  const Eigen::VectorXd theta = read_theta(in, model);
  const ffsr::BasePose base = read_base(in);
  ffsr::Target target = read_target(in);
  read_motion(in, target);
  const double speed = in.real(0.2);
  const ffsr::ContactParams p = read_params(in);
  const std::string law = read_law(in);
  ffsr::MultibodyContactOptions opt;
  static const double rtols[] = {1e-10, 1e-8, 1e-6, 1e-3};
  opt.rtol = rtols[in.byte(0) % 4];
  opt.max_num_steps = 150;  // bounded work per input (the paper's contact needs about 100 steps)
  opt.max_duration = in.real(0);
  opt.record_series = true;
  returns_or_ffsr_error("simulate_contact", [&] {
    const ffsr::MultibodyContactResult r =
        ffsr::simulate_contact(model, base, theta, model.end_effector(), target, speed, p, law, opt);
    for (double x : {r.approach_velocity, r.integrated_effective_mass, r.f_max, r.t_at_f_max,
                     r.delta_at_f_max, r.delta_max, r.contact_duration, r.separation_velocity, r.restitution,
                     r.energy_start, r.energy_end})
      require_finite(x, "simulate_contact result");
    require_finite(r.momentum_start, "momentum_start");
    require_finite(r.momentum_end, "momentum_end");
    for (const auto& s : r.series) {
      require_finite(s.t, "series t");
      require_finite(s.force, "series F");
      require_finite(s.delta, "series delta");
    }
    if (!(r.f_max >= 0)) fail("negative peak force");
  });
}

// --- 3: the planner, with a short duration (<= 2 s, step >= 0.2 s) --------------------------------
inline void check_plan_capture(Input& in, const ffsr::Model& model) {
  ffsr::CaptureProblem pb;
  pb.model = &model;
  pb.frame = model.end_effector();
  pb.theta = read_theta(in, model);
  pb.base = read_base(in);
  pb.target = read_target(in);
  read_motion(in, pb.target);
  pb.contact = read_params(in);
  pb.law = read_law(in);
  pb.approach_speed = in.real(0.2);
  ffsr::CaptureTask task;
  const uint8_t tb = in.byte(model.n() == 3 ? 0x03 : 0x10);  // 3-DOF: position xy; 7-DOF: pose
  task.kind = (tb & 0x10) ? ffsr::CaptureTask::Kind::Pose : ffsr::CaptureTask::Kind::Position;
  task.axes = {(tb & 1) != 0, (tb & 2) != 0, (tb & 4) != 0};
  if (tb & 0x20)
    task.final_orientation = ffsr::rotation_from_rpy(ffsr::Vector3(in.real(0), in.real(0), in.real(0)));
  ffsr::CaptureOptions opt;
  opt.duration = in.real(2);
  if (std::isfinite(opt.duration) && opt.duration > 2) opt.duration = 2;  // bounded work per input
  opt.step = in.real(0.2);
  if (std::isfinite(opt.step) && opt.step > 0 && opt.step < 0.2) opt.step = 0.2;  // at most 10 RK4 steps
  opt.gain = in.real(0);
  opt.feedback = in.real(1);
  opt.tolerance = in.real(1e-3);
  opt.objective =
      (tb & 0x40) ? ffsr::CaptureObjective::ExactMaxForce : ffsr::CaptureObjective::IntegratedEffectiveMass;
  opt.record_series = true;
  returns_or_ffsr_error("plan_capture", [&] {
    const ffsr::CaptureResult r = ffsr::plan_capture(pb, task, opt);
    require_finite(r.theta, "theta(T)");
    require_finite(r.base.position, "base position(T)");
    require_finite(r.base.orientation.coeffs(), "base attitude(T)");
    require_finite(r.end_effector, "end-effector(T)");
    require_finite(r.capture_point, "capture point");
    for (double x :
         {r.tracking_error, r.orientation_error, r.base_position_drift, r.base_attitude_drift, r.M_ie,
          r.approach_velocity, r.f_max_closed_form, r.f_max_exact, r.max_momentum, r.max_body_momentum,
          r.max_quaternion_error, r.max_com_drift, r.max_tracking_error, r.min_singular_value})
      require_finite(x, "plan_capture result");
    for (const auto& s : r.series) {
      require_finite(s.theta, "series theta");
      require_finite(s.end_effector, "series end-effector");
      require_finite(s.M_ie, "series M_ie");
      require_finite(s.f_max_estimate, "series F_max");
    }
  });
}

/// fuzz_numeric: the selector byte picks the entry point (low 2 bits) and the robot (bit 2).
inline void check_numeric_input(const uint8_t* data, size_t size) {
  Input in(data, size);
  const uint8_t sel = in.byte(0);
  const ffsr::Model& model = paper_robot((sel & 4) != 0);
  switch (sel & 3) {
    case 0:
      check_effective_mass(in, model);
      break;
    case 1:
      check_contact_law(in);
      break;
    case 2:
      check_simulate_contact(in, model);
      break;
    default:
      check_plan_capture(in, model);
      break;
  }
}

}  // namespace ffsr_fuzz
