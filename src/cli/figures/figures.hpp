// src/cli/figures/figures.hpp -- every figure of the command: the paper's figures as plot::Figure descriptions, built from the result
// structs the JSON and CSV are written from (CaptureResult, the contact rows, a map grid).
#pragma once

#include "figures/plot.hpp"

#include "ffsr/geometry/shape.hpp"
#include "ffsr/optimize/capture.hpp"

#include <optional>
#include <string>
#include <vector>

namespace ffsr::cli::figures {

/// One capture run to draw (plain, the paper's method, a global run, ...): its label in legends
/// and file names, its result with the recorded series, and its task (for the singular value).
struct CaptureRun {
  std::string label;  ///< e.g. "plain"; the file is capture_<label>
  const CaptureResult* result = nullptr;
  CaptureTask task;
  long reconfiguration_samples = 0;  ///< the first samples of the series that are a reconfiguration
  /// With shapes: the smallest distance along the path (its pair marked); null: none.
  const ClearanceReport* clearance = nullptr;
};

/// The collision shapes of a scenario with geometry, drawn as they are in the capture pictures.
struct SceneShapes {
  std::vector<std::vector<Shape>> bodies;  ///< bodies[b]: the shapes of body b (body frame)
  std::optional<Shape> target;             ///< the target's shape (target frame); none: a schematic box
};

/// Figures 10, 11, 13-15: for each run the arm at eight instants (links as segments, joints as
/// dots, the base as a box, fading from early to late), the end-effector path and the target at T
/// with its contact point and normal -- in the plane for a planar robot, else an oblique view and a
/// top view. Then "histories" (M_ie, closed-form F_max, base attitude drift and the task's smallest
/// singular value against time, all runs on shared axes) and "joints" (the joint angles).
/// With `shapes`: the target's shape at T instead of the schematic box, the bus and the links'
/// shapes with the arm at T, and for a run with a clearance report its closest pair (the nearest
/// points joined, with the bodies and the target at that instant, faint).
/// Forward kinematics and the task Jacobian are recomputed from each recorded state.
/// Reads the runs' series (record_series must have been on).
std::vector<plot::Figure> capture(const Model& model, int frame, const Target& target_at_start,
                                  double duration, const std::vector<CaptureRun>& runs,
                                  const SceneShapes* shapes = nullptr);

/// A closed-loop run of `closed-loop` (plain data: the command copies it from the simulation's
/// recorded series) beside the open-loop plan it follows.
struct ClosedLoopSeries {
  std::vector<std::string> joint_names;
  std::vector<double> t;                     ///< s
  std::vector<Eigen::VectorXd> theta;        ///< rad, one per t
  std::vector<Eigen::VectorXd> lag;          ///< command - joint rate, rad/s, one per t
  std::vector<Eigen::VectorXd> torque;       ///< N m, one per t
  std::vector<double> reference_error;       ///< |p_e - x_d|, m, one per t
  double torque_limit = 0;                   ///< N m
  const CaptureResult* open_loop = nullptr;  ///< the plan, with its recorded series
  std::string title;
};
/// "closed_loop": the joint angles of the closed loop (solid) and of the open-loop plan (dashed),
/// the end-effector's distance to the reference line, the joint torques with their limit and the
/// rate loops' lag, against time.
plot::Figure closed_loop(const ClosedLoopSeries& s);

/// The post-capture runs of `detumble` (plain data: the command copies them from the runs' series),
/// SI units and radians as recorded.
struct DetumbleSeries {
  std::string title;
  std::vector<std::string> joint_names;
  std::vector<double> torque_limit;  ///< N m, one per joint
  double rest_rate = 0;              ///< rad/s, the at-rest threshold
  bool stack_rate = false;           ///< the stack's rate is part of the rest test (stop-stack-spin)
  double wheel_bound = 0;            ///< the wheels' momentum per axis, N m s; 0: no reaction wheels
  struct Run {
    std::string label;  ///< in legends: the main job's run it starts from (plain, optimized, global)
    int color = 0;      ///< palette index
    std::vector<double> t, joint_rate, relative_rate, stack_rate;  ///< s, rad/s
    std::vector<double> force, moment, attitude, energy;           ///< N, N m, rad, J
    std::vector<Eigen::VectorXd> rate, torque;                     ///< rad/s, N m; one per t
    std::vector<Eigen::Vector3d> wheel;                            ///< N m s, base frame; one per t
  };
  std::vector<Run> runs;
};
/// "detumble" (three rows of two panels): against time, the joint rates; the rest test's rates (largest joint rate, the gripper's
/// rate relative to the base, the stack's) with the threshold; the joint torques with their limits;
/// the gripper's force and moment on the target; the base's rotation since the grasp; the wheels'
/// momentum per axis with its bound (with reaction wheels), else the kinetic energy. Joints by colour
/// and runs by line style in the joint panels, runs by colour elsewhere. InputError on series of
/// unequal lengths or joint counts.
plot::Figure detumble(const DetumbleSeries& s);

/// One contact run of `contact`: F(t), delta(t) and the two marked points of Figure 3.
struct ContactCurve {
  std::string law;
  std::vector<double> t, delta, force;           ///< s, m, N
  double delta_max = 0, force_at_delta_max = 0;  ///< (delta_max, F'_max)
  double delta_at_f_max = 0, f_max = 0;          ///< (delta'_max, F_max)
};
/// Figure 3: the F-delta hysteresis loop(s) with the two points marked, and F(t).
plot::Figure contact(const std::vector<ContactCurve>& curves, double M_ie, double approach_velocity);

/// One xi study (Figures 4-6): xi of each law (percent) against one parameter.
struct XiStudy {
  std::string name, title, xlabel;
  bool log_x = false;
  std::vector<double> x;
  std::vector<std::string> laws;
  std::vector<std::vector<double>> xi;  ///< xi[law][k], percent
};
plot::Figure xi(const XiStudy& study);

/// A Pareto front of (M_ie, base angular rate jump) with the runs of the main job (plain data:
/// the command copies it from ParetoFront).
struct ParetoSeries {
  std::string title;               ///< names the scenario in the figure's title (may be empty)
  std::vector<double> mass, rate;  ///< the front, kg and deg/s, M_ie increasing
  size_t knee = 0;                 ///< index in mass/rate
  struct Run {
    std::string label;  ///< e.g. "plain run"
    double mass = 0, rate = 0;
  };
  std::vector<Run> runs;
  /// the second axis (`rate` holds its values): its label, its name in the legend and its unit
  std::string y_label = "base angular rate jump |Δω#d0#u| (deg/s)", y_name = "rate", y_unit = "deg/s";
};
/// "pareto": the front as a line with markers, its two ends (the single-objective optima) and its
/// knee marked, the runs as points with their values in the legend. When a run lies far from the
/// front (outside its extent grown by a quarter on every side), a second panel below holds the front
/// as one line and every run; with none, one panel. InputError on an empty front, unequal
/// lengths, a knee out of range or a value that is not finite.
plot::Figure pareto(const ParetoSeries& s);

/// Values over a grid of joint angles: values[i0 * n1 * n2 + i1 * n2 + i2] (last axis fastest).
struct Grid {
  std::vector<std::string> axis_labels;   ///< e.g. "θ1 (deg)"
  std::vector<std::vector<double>> axes;  ///< ascending, 2 or 3 axes
  std::vector<double> values;
  std::string value_label = "M_ie (kg)";
  /// Checks axes and the number of values; InputError otherwise.
  void validate(size_t dims) const;
};
/// Figure 9 for two varied joints: heat map, contour lines, colour bar, the maximum marked.
plot::Figure map_heat(const Grid& grid, const std::string& name, const std::string& title);
/// Figure 9 for three varied joints: the three orthogonal slices through the grid point nearest to
/// `point` (one value per axis), each a heat map; the maximum of the whole grid is named in the title.
plot::Figure map_slices(const Grid& grid, const std::vector<double>& point, const std::string& name,
                        const std::string& title);
/// Figure 8: the grid as coloured points in 3-D (at most `max_points`, evenly strided).
plot::Figure map_cloud(const Grid& grid, const std::string& name, const std::string& title,
                       size_t max_points = 12000);

/// The Monte Carlo of `robust`: every configuration's F_max over the samples and its 95th percentile
/// (the estimator's), drawn as empirical CDFs and histograms ("robust").
struct RobustSeries {
  std::string title;
  bool stiffness_conditional = false;  ///< the p95 is the law's conditional on the stiffness
  struct Configuration {
    std::string name;
    std::vector<double> f_max;  ///< N, by sample
    double p95 = 0;             ///< N
  };
  std::vector<Configuration> configurations;
};
plot::Figure robust(const RobustSeries& s);

}  // namespace ffsr::cli::figures
