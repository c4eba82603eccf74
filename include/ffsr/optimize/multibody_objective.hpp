// ffsr/optimize/multibody_objective.hpp -- the multibody-force objective's CVODE run for the capture
// objective (objective.hpp), and evaluate_capture, the objective at one configuration of a capture
// problem whatever its kind. Needs SUNDIALS CVODE (ffsr::cvode).
#pragma once

#include "ffsr/optimize/objective.hpp"
#include "ffsr/simulate/multibody.hpp"

namespace ffsr {

/// The CVODE robot-plus-target peak of a capture problem (simulate_contact with the problem's
/// contact, law and approach speed, the target at T, the multibody options: servoed joints and
/// armature). A view: pb, the target and the options must outlive it.
class CvodeMultibodyPeak final : public MultibodyPeak {
 public:
  CvodeMultibodyPeak(const CaptureProblem& pb, const Target& target_at_capture,
                     const MultibodyContactOptions& o)
      : pb_(pb), target_(target_at_capture), options_(o) {}
  double operator()(const BasePose& base, const Eigen::VectorXd& theta) const override {
    return simulate_contact(*pb_.model, base, theta, pb_.frame, target_, pb_.approach_speed, pb_.contact,
                            pb_.law, options_)
        .f_max;
  }

 private:
  const CaptureProblem& pb_;
  const Target& target_;
  const MultibodyContactOptions& options_;
};

/// Value of the objective at a capture configuration (base at T): CaptureEvaluator::evaluate for the
/// problem, the kind, the multibody options (multibody-force) and the robust objective (required for
/// robust-force). Runs crba (and CVODE for the multibody objective).
inline ManifoldPoint evaluate_capture(const CaptureProblem& pb, const CaptureSetup& s, const BasePose& base,
                                      const Eigen::VectorXd& theta, GlobalObjective objective,
                                      const MultibodyContactOptions& mo = {},
                                      RobustForceObjective* robust = nullptr) {
  Data data(*pb.model);
  const CvodeMultibodyPeak peak(pb, s.capture.target, mo);
  return CaptureEvaluator(pb, s, objective, &peak, robust).evaluate(data, base, theta);
}

}  // namespace ffsr
