// ffsr-optimize: the joint-model flags of `contact` and `map` (algorithm/joint_models.hpp):
// --contact-joints (free, locked, armature; `contact` also takes all), --armature and, for the
// multibody reference of `contact`, --joint-stiffness and --joint-damping.
#pragma once

#include "common.hpp"

#include "ffsr/algorithm/joint_models.hpp"

#include <string>
#include <vector>

namespace ffsr::cli {

struct JointOptions {
  std::string model = "free";
  std::string armature, stiffness, damping;  ///< comma-separated; empty: 0 for every joint

  void add_to(CLI::App& app, bool multibody) {
    app.add_option(multibody ? "--contact-joints,--joints" : "--contact-joints", model,
                   multibody ? "The joints during the contact: free, locked, armature, or all (the three "
                               "closed-form predictions beside the multibody run)"
                             : "The joints during the contact: free, locked or armature")
        ->capture_default_str();
    app.add_option("--armature", armature,
                   "Reflected rotor inertia per joint, kg m^2 (kg prismatic): one value or one per joint");
    if (!multibody) return;
    app.add_option(
        "--joint-stiffness", stiffness,
        "Multibody run: joint PD stiffness holding the pre-contact rates, N m/rad (one or per joint)");
    app.add_option("--joint-damping", damping,
                   "Multibody run: joint PD damping, N m s/rad (one or per joint)");
  }

  static Eigen::VectorXd values(const std::string& text, const Model& m, const std::string& flag) {
    return per_joint_values(text.empty() ? std::vector<double>{} : parse_list(text, flag, {}), m, flag);
  }

  /// The chosen model ("all" stands for each in turn: `contact` asks for them by JointModel).
  ContactJoints build(const Model& m) const {
    const JointModel jm = model == "all" ? JointModel::Free : parse_joint_model(model, "--contact-joints");
    return {jm, values(armature, m, "--armature")};
  }
  bool all() const { return model == "all"; }
};

}  // namespace ffsr::cli
