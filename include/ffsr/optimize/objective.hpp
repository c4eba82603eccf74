// ffsr/optimize/objective.hpp -- the capture objective: what a capture configuration is worth, in one
// evaluator that every path calls (the manifold search and its branches, the reaching runs and their
// checks, the paper's planner's reports, the Pareto front and the base-rate constraint, the robust
// samples, the closed loop's report and the command's subcommands), so that the joint model of the
// contact and the objective kind reach all of them.
#pragma once

#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/optimize/capture_problem.hpp"
#include "ffsr/uncertainty/robust_objective.hpp"

// At a capture configuration (the base pose at T and the joint angles theta), with u the target's
// contact normal at T and b the target's inverse mass along it (Target::inverse_mass_along_normal):
//   M_ie = 1 / (u^T Lambda_v^-1 u + b)                                           (Eq. 14)
// with the robot's inverse mass u^T Lambda_v^-1 u of the joint model (algorithm/joint_models.hpp:
// free, the paper's; locked, the composite rigid body; armature, rotor inertias on H's diagonal).
// The objective kinds:
//   mass             M_ie, kg
//   exact-force      the exact single-body peak (Eq. 16) at M_ie, N: a monotone function of M_ie
//   multibody-force  the CVODE robot-plus-target peak (simulate/multibody.hpp, its servoed joints and
//                    armature from MultibodyContactOptions), N; given to the evaluator as a
//                    MultibodyPeak (multibody_objective.hpp), so that this header needs Eigen only
//   robust-force     CVaR_95 of the exact peak over a fixed sample set
//                    (uncertainty/robust_objective.hpp) with Lambda^-1 of the joint model, N
// What a search minimizes (search_value): M_ie for mass and exact-force (the same optimum) and for
// multibody-force (no gradient: the local optima of M_ie are then ranked by the CVODE peak), CVaR_95
// for robust-force; each with its analytic gradient in theta at a fixed base pose.
//
// CaptureEvaluator is a view (pointers to the problem, the law, the joint model, the options): cheap
// to make, allocation-free to call for M_ie and its gradient (Data holds the workspace).

namespace ffsr {

enum class GlobalObjective { Mass, ExactForce, MultibodyForce, RobustForce };

/// The objective's name as the command spells it.
inline const char* objective_name(GlobalObjective o) {
  switch (o) {
    case GlobalObjective::Mass:
      return "mass";
    case GlobalObjective::ExactForce:
      return "exact-force";
    case GlobalObjective::MultibodyForce:
      return "multibody-force";
    case GlobalObjective::RobustForce:
      return "robust-force";
  }
  return "?";
}

/// A configuration on the capture manifold with its M_ie and objective value.
struct ManifoldPoint {
  Eigen::VectorXd theta;
  double M_ie = 0;
  double objective = 0;  ///< kg (mass) or N (exact-force, multibody-force, robust-force: CVaR_95)
};

/// The multibody-force objective's value at a configuration (base pose at T, joint angles): the CVODE
/// robot-plus-target peak, N. CvodeMultibodyPeak (multibody_objective.hpp) is the one in use.
class MultibodyPeak {
 public:
  virtual ~MultibodyPeak() = default;
  virtual double operator()(const BasePose& base, const Eigen::VectorXd& theta) const = 0;
};

/// The capture objective (see the notes after the includes) of one contact: a robot and its contact frame,
/// the target at the capture (normal u and inverse mass b), the law, the joint model and the kind.
class CaptureEvaluator {
 public:
  /// The objective of a capture problem: pb's model, frame and joint model (pb.joints), the contact of
  /// the setup (the target at T, the law at the capture's approach velocity). multibody-force needs
  /// `peak`, robust-force `robust` (InputError at their first use otherwise). pb, s, peak and robust
  /// must outlive the evaluator.
  CaptureEvaluator(const CaptureProblem& pb, const CaptureSetup& s,
                   GlobalObjective kind = GlobalObjective::Mass, const MultibodyPeak* peak = nullptr,
                   RobustForceObjective* robust = nullptr)
      : model_(pb.model),
        frame_(pb.frame),
        u_(s.capture.u_cap),
        b_(s.capture.target_inv_mass),
        law_(&s.capture.law),
        joints_(&pb.joints),
        kind_(kind),
        peak_(peak),
        robust_(robust) {
    if (!model_) FFSR_THROW(InputError("CaptureEvaluator: no model"));
  }

  /// A contact with `target` as it is at the capture (its attitude gives u = R_t u_n) under `law`, for
  /// the kinds that are functions of M_ie (mass, exact-force). law may be null: M_ie alone (the forces
  /// and the disturbance then throw InputError). model, law and joints must outlive the evaluator.
  CaptureEvaluator(const Model& model, int frame, const Target& target, const AnyContactLaw* law,
                   const ContactJoints& joints, GlobalObjective kind = GlobalObjective::Mass)
      : model_(&model),
        frame_(frame),
        u_(target.normal_world()),
        b_(target.inverse_mass_along_normal()),
        law_(law),
        joints_(&joints),
        kind_(kind) {
    if (kind == GlobalObjective::MultibodyForce || kind == GlobalObjective::RobustForce)
      FFSR_THROW(InputError(detail::str("CaptureEvaluator: the ", objective_name(kind),
                                   " objective needs the capture problem")));
  }

  const Model& model() const { return *model_; }
  int frame() const { return frame_; }
  const ContactJoints& joints() const { return *joints_; }
  GlobalObjective kind() const { return kind_; }
  const AnyContactLaw& law() const {
    if (!law_) FFSR_THROW(InputError("CaptureEvaluator: no contact law given (M_ie only)"));
    return *law_;
  }
  const Vector3& normal() const { return u_; }
  double target_inverse_mass() const { return b_; }

  /// M_ie at the configuration of the last crba. Reads data.H and the kinematics. Writes data.L,
  /// data.w, data.y.
  double mass_at(Data& data) const {
    return 1.0 / (inverse_effective_mass(*model_, data, frame_, u_, *joints_) + b_);
  }

  /// M_ie at (base, theta). Runs crba.
  double mass(Data& data, const BasePose& base, const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    crba(*model_, data, base, theta);
    return mass_at(data);
  }

  /// M_ie at (base, theta) by the faster path for many evaluations (maps): integrated_effective_mass
  /// under the joint model (the articulated-body recursion, or the composite route for few joints;
  /// the same M_ie as mass to rounding). Writes the kinematics and the routes' fields.
  double mass_fast(Data& data, const BasePose& base, const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    return integrated_effective_mass(*model_, data, base, theta, frame_, u_, b_, *joints_);
  }

  /// M_ie and its analytic gradient in theta (size n) at a fixed base pose
  /// (integrated_effective_mass_gradient_dense of the joint model). Runs crba. Writes data and grad.
  double mass_gradient(Data& data, const BasePose& base, const Eigen::Ref<const Eigen::VectorXd>& theta,
                       Eigen::Ref<Eigen::VectorXd> grad) const {
    return integrated_effective_mass_gradient_dense(*model_, data, base, theta, frame_, u_, b_, *joints_,
                                                    grad);
  }

  /// The same at the configuration of the last crba (integrated_effective_mass_gradient_at): for a
  /// caller that has just run crba at (base, theta). Writes data.L, data.w, data.y, data.V, data.F, grad.
  double mass_gradient_at(Data& data, Eigen::Ref<Eigen::VectorXd> grad) const {
    return integrated_effective_mass_gradient_at(*model_, data, frame_, u_, b_, *joints_, grad);
  }

  /// The closed-form (Eq. 24) and exact (Eq. 16) single-body peaks at a given M_ie, N.
  double f_max_closed_form(double M_ie) const { return max_force_closed_form(law(), M_ie); }
  double f_max_exact(double M_ie) const { return max_force_exact(law(), M_ie); }

  /// The objective of a kind that is a function of M_ie: M_ie (mass), the exact peak at it
  /// (exact-force). InputError for the other kinds.
  double of_mass(double M_ie) const {
    if (kind_ == GlobalObjective::Mass) return M_ie;
    if (kind_ != GlobalObjective::ExactForce)
      FFSR_THROW(InputError(
          detail::str("CaptureEvaluator: the ", objective_name(kind_), " objective is no function of M_ie")));
    return f_max_exact(M_ie);
  }

  /// The robot's 6x6 inverse inertia at the contact frame under the joint model (Lambda^-1 of
  /// inverse_inertia_matrix), at the configuration of the last crba. Writes data.L, data.w, data.y.
  Matrix6 inverse_inertia_at(Data& data) const {
    return inverse_inertia_matrix(*model_, data, frame_, *joints_);
  }

  /// The same at (base, theta). Runs crba.
  Matrix6 inverse_inertia(Data& data, const BasePose& base,
                          const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    crba(*model_, data, base, theta);
    return inverse_inertia_at(data);
  }

  /// robust-force's measure (CVaR_95 and p95 of the exact peak over the sample set) at (base, theta),
  /// Lambda^-1 of the joint model. Runs crba.
  RobustForceObjective::Value robust_value(Data& data, const BasePose& base,
                                           const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    return robust().value(inverse_inertia(data, base, theta));
  }

  /// The value a search compares (see the notes after the includes): M_ie, or CVaR_95 for robust-force.
  /// Writes M (M_ie). Runs crba.
  double search_value(Data& data, const BasePose& base, const Eigen::Ref<const Eigen::VectorXd>& theta,
                      double& M) const {
    M = mass(data, base, theta);
    if (kind_ != GlobalObjective::RobustForce) return M;
    return robust().value(inverse_inertia_at(data)).cvar95;
  }

  /// search_value with its analytic gradient in theta (size n) at a fixed base pose. Runs crba.
  double search_value_gradient(Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta,
                               Eigen::Ref<Eigen::VectorXd> grad) const {
    if (kind_ == GlobalObjective::RobustForce)
      return robust().value_and_gradient(*model_, data, base, theta, frame_, *joints_, grad);
    return mass_gradient(data, base, theta, grad);
  }

  /// The objective at (base, theta): theta, M_ie and the kind's value (one CVODE run for
  /// multibody-force). Runs crba.
  ManifoldPoint evaluate(Data& data, const BasePose& base, const Eigen::VectorXd& theta) const {
    ManifoldPoint p{theta, mass(data, base, theta), 0};
    switch (kind_) {
      case GlobalObjective::Mass:
      case GlobalObjective::ExactForce:
        p.objective = of_mass(p.M_ie);
        break;
      case GlobalObjective::MultibodyForce:
        if (!peak_) FFSR_THROW(InputError("CaptureEvaluator: the multibody-force objective needs its CVODE run"));
        p.objective = (*peak_)(base, theta);
        break;
      case GlobalObjective::RobustForce:
        p.objective = robust().value(inverse_inertia_at(data)).cvar95;
        break;
    }
    return p;
  }

  /// M_ie and the jump of the base's velocity [v_0; w_0] per unit impulse along u (per_unit;
  /// base_velocity_per_unit_impulse) under the joint model, at the configuration of the last crba:
  /// the Pareto front's two objectives without the law's restitution solve. Writes data.L, data.w,
  /// data.y.
  double mass_and_base_response_at(Data& data, Vector6& per_unit) const {
    double inverse_mass = 0;
    per_unit = base_velocity_per_unit_impulse(*model_, data, frame_, u_, *joints_, inverse_mass);
    return 1.0 / (inverse_mass + b_);
  }

  /// The impact disturbance of the base at (base, theta) under the joint model (its M_ie and the
  /// base's jump; algorithm/base_disturbance.hpp). Runs crba.
  BaseDisturbance disturbance(Data& data, const BasePose& base,
                              const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    crba(*model_, data, base, theta);
    return base_disturbance_at(*model_, data, frame_, u_, b_, law(), *joints_);
  }

 private:
  RobustForceObjective& robust() const {
    if (!robust_) FFSR_THROW(InputError("CaptureEvaluator: the robust-force objective needs its sample set"));
    return *robust_;
  }

  const Model* model_;
  int frame_;
  Vector3 u_;
  double b_;
  const AnyContactLaw* law_;
  const ContactJoints* joints_;
  GlobalObjective kind_;
  const MultibodyPeak* peak_ = nullptr;
  RobustForceObjective* robust_ = nullptr;
};

}  // namespace ffsr
