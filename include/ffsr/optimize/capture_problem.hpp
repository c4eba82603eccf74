// ffsr/optimize/capture_problem.hpp -- what a capture run is given and what it returns (Section 4):
// the task (which rows of J_f it constrains), the options of the rate law and the integration, the
// problem (robot, end-effector, initial state, target, contact law), the setup that follows from
// them (prepare_capture in capture.hpp), and the result with the monitors' record.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/model/data.hpp"
#include "ffsr/model/target.hpp"
#include "ffsr/optimize/line_reference.hpp"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ffsr {

/// What the end-effector must follow.
struct CaptureTask {
  enum class Kind { Position, Pose };
  Kind kind = Kind::Position;
  /// Position task: which inertial axes are constrained (x, y, z). The planar robot uses x and y.
  std::array<bool, 3> axes{true, true, true};
  /// Pose task: final end-effector orientation (inertial), reached by slerp; empty: hold the initial one.
  std::optional<Matrix3> final_orientation;
  /// Number of task rows.
  int rows() const {
    if (kind == Kind::Pose) return 6;
    return int(axes[0]) + int(axes[1]) + int(axes[2]);
  }
};

enum class CaptureObjective { IntegratedEffectiveMass, ExactMaxForce };

/// A filter of a capture run's joint rates inside the task's null space, applied at every evaluation
/// of the rate law after the null-space policy and the joint-rate scaling (for example the clearance
/// barrier of optimize/clearance.hpp, which keeps the distances to obstacles). `filter` receives the
/// kinematics and data.H of (base, theta) (crba, frame_jacobian, generalized_jacobian run), the time,
/// the null-space projector N of the task (and of the held rows, with hold_base_attitude) and the
/// joint rates, which it may change by adding N v only (the task rates stay). It keeps per-run state,
/// so each run makes its own (CaptureOptions::rate_guard).
class RateGuard {
 public:
  virtual ~RateGuard() = default;
  virtual void filter(const Model& model, const Data& data, double t, const Eigen::MatrixXd& N,
                      Eigen::VectorXd& theta_dot) = 0;
};

struct CaptureOptions {
  double duration = 180.0;              ///< T, s
  double step = 0.1;                    ///< RK4 step, s
  double gain = 0.0;                    ///< rho of Eq. 30 (< 0 lowers the objective; 0: plain tracking)
  double feedback = 1.0;                ///< k_p, 1/s, on the position (m) and orientation (rad) error
  double tolerance = 1e-3;              ///< required end-effector position error at T, m
  double orientation_tolerance = 1e-2;  ///< pose task: required orientation error at T, rad
  CaptureObjective objective = CaptureObjective::IntegratedEffectiveMass;
  double singular_value_threshold = 1e-3;  ///< below it the pseudo-inverse is damped
  double max_damping = 1e-2;               ///< largest damping (lambda) of the damped least squares
  bool record_series = false;
  int record_every = 1;                  ///< keep every k-th step in the series
  std::function<void(double)> progress;  ///< called with the fraction done (0..1), optional
  double max_joint_rate = 0;  ///< rad/s; the null-space term is scaled down to respect it (0: not limited)
  /// Reaction-null-space approach: hold the base's angular velocity at zero (base_attitude.hpp)
  bool hold_base_attitude = false;
  /// Makes the run's joint-rate filter (RateGuard), called once per run; empty: none. The filter's
  /// correction is not scaled by max_joint_rate (the largest joint rate is still recorded).
  std::function<std::unique_ptr<RateGuard>()> rate_guard;
};

/// The capture problem: robot, end-effector, initial state, target (its initial state at t = 0),
/// contact law and approach speed at the capture.
struct CaptureProblem {
  const Model* model = nullptr;
  int frame = -1;
  BasePose base;
  Eigen::VectorXd theta;
  Target target;
  ContactParams contact;
  std::string law = "herbert-mcwhannell";
  double approach_speed = 0.2;
  /// The joints during the contact: the model of M_ie in the objective and the reported M_ie.
  ContactJoints joints;
};

struct CaptureSample {
  double t = 0;
  Eigen::VectorXd theta;
  BasePose base;
  Vector3 end_effector = Vector3::Zero();
  double M_ie = 0;            ///< with the target at the capture time
  double f_max_estimate = 0;  ///< closed-form F_max at that M_ie
};

struct CaptureResult {
  Eigen::VectorXd theta;  ///< capture configuration (rad)
  BasePose base;          ///< base pose at T
  Vector3 end_effector = Vector3::Zero();
  Vector3 capture_point = Vector3::Zero();
  double tracking_error = 0;       ///< |p_e(T) - capture point| on the task's constrained axes, m
  double capture_distance = 0;     ///< |p_e(T) - capture point| in 3-D (differs for a task on fewer axes), m
  double orientation_error = 0;    ///< pose task: angle between the reached and desired orientation, rad
  double base_position_drift = 0;  ///< |p_0(T) - p_0(0)|, m
  double base_attitude_drift = 0;  ///< rotation angle between the base attitudes at 0 and T, rad
  double M_ie = 0;
  double approach_velocity = 0;  ///< delta_dot^- at the capture
  double f_max_closed_form = 0;
  double f_max_exact = 0;
  double max_momentum = 0;          ///< largest |total momentum| along the run (checked each step)
  double max_body_momentum = 0;     ///< largest |body momentum| along the run, for scale
  double max_quaternion_error = 0;  ///< largest | |q| - 1 | before renormalization
  double max_com_drift = 0;         ///< largest motion of the system centre of mass (zero momentum: ~0)
  double max_tracking_error = 0;    ///< largest end-effector position error along the line, m
  double min_singular_value = 0;    ///< smallest task singular value seen
  long damped_steps = 0;            ///< evaluations where the pseudo-inverse was damped
  double max_joint_rate = 0;        ///< largest |theta_dot_k| over every evaluation, rad/s
  long steps = 0;
  std::vector<CaptureSample> series;
};

/// The capture at T, which follows from the target, the task and the contact, not from the robot's
/// initial state: the target then, the capture point and normal, the contact law at the capture's
/// approach velocity, the end-effector's orientation then. A run from another state towards the same
/// capture (the approach after a reconfiguration, reconfigure.hpp) takes it whole.
struct CaptureAtT {
  Target target;                        ///< the target at T
  Vector3 x_cap = Vector3::Zero();      ///< capture point
  Vector3 u_cap = Vector3::UnitX();     ///< inertial contact normal at T
  double target_inv_mass = 0;           ///< the target's inverse mass along the normal (Eq. 14)
  double v_in = 0;                      ///< delta_dot^- at the capture
  AnyContactLaw law;                    ///< the contact law at v_in
  Matrix3 R_end = Matrix3::Identity();  ///< pose task: the end-effector orientation at T
};

/// Everything a capture run needs that follows from the problem: the capture at T, the line reference
/// from the initial state and the task rows. Made (and every input checked) by prepare_capture.
struct CaptureSetup {
  CaptureAtT capture;     ///< the target, the capture point and normal, the law, the orientation at T
  LineReference line;     ///< from the initial end-effector pose to the capture
  std::vector<int> rows;  ///< rows of J_f (and of the 6-D error) that the task constrains
  /// hold_base_attitude: Q (3 x r), the base angular velocities held at zero (base_attitude.hpp); else empty
  Eigen::MatrixXd attitude_basis;
  /// hold_base_attitude: each joint's share of the freedom the task and the held rows leave at the
  /// initial state (held_freedom_shares); else empty
  Eigen::VectorXd held_freedom;
};

}  // namespace ffsr
