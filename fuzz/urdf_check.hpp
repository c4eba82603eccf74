// fuzz/urdf_check.hpp -- the fuzz_urdf check: URDF text -> model_from_urdf_string; an accepted model
// must give finite H, J_f and M_ie at zero and at pseudo-random configurations derived from the input.
#pragma once

#include "fuzz_checks.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <string>

namespace ffsr_fuzz {

/// The checks on one evaluated configuration of an accepted model.
inline void check_configuration(const ffsr::Model& model, ffsr::Data& data, const ffsr::BasePose& base,
                                const Eigen::VectorXd& theta, int frame, const ffsr::Target& target) {
  // crba may refuse (NumericalError) when the model's finite values overflow H; it must not return NaN.
  if (!returns_or_ffsr_error("crba", [&] { ffsr::crba(model, data, base, theta); })) return;
  require_finite(data.H, "H");
  returns_or_ffsr_error("integrated_effective_mass", [&] {
    const double M_ie = ffsr::integrated_effective_mass(model, data, base, theta, frame, target);
    require_finite(M_ie, "M_ie");
    if (!(M_ie > 0)) fail("M_ie is not positive: " + std::to_string(M_ie));
  });
  returns_or_ffsr_error("integrated_effective_mass_dense", [&] {
    const double M_ie = ffsr::integrated_effective_mass_dense(model, data, base, theta, frame, target);
    require_finite(M_ie, "M_ie (dense)");
    if (!(M_ie > 0)) fail("M_ie (dense) is not positive: " + std::to_string(M_ie));
  });
  returns_or_ffsr_error("effective_mass", [&] {
    const double m_e = ffsr::effective_mass(model, data, base, theta, frame, target.normal_world());
    require_finite(m_e, "m_e");
  });
  returns_or_ffsr_error("generalized_jacobian", [&] {
    const Eigen::MatrixXd& Jf = ffsr::generalized_jacobian(model, data, base, theta, frame);
    require_finite(data.J, "J_bm");
    require_finite(Jf, "J_f");
  });
}

/// fuzz_urdf: bytes -> model_from_urdf_string(text). A rejected file must be an ffsr::Error.
inline void check_urdf_input(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ffsr::Model model = [&] {
    try {
      return ffsr::model_from_urdf_string(text, "fuzz.urdf");
    } catch (const ffsr::Error&) {
      return ffsr::Model();
    } catch (const std::exception& e) {
      fail(std::string("model_from_urdf_string: unexpected exception ") + typeid(e).name() + ": " + e.what());
    }
  }();
  if (model.bodies().empty()) return;  // rejected with an ffsr::Error
  if (model.n() < 1) fail("accepted a model without a moving joint");
  if (model.end_effector() < 0 || model.end_effector() >= static_cast<int>(model.frames().size()))
    fail("accepted a model with an end-effector out of range");
  for (const auto& b : model.bodies()) {
    require_finite(b.inertia.mass, "body mass");
    require_finite(b.inertia.com, "body com");
    require_finite(b.inertia.I, "body inertia");
    require_finite(b.tree.p, "joint origin");
    require_finite(b.tree.R, "joint rotation");
    require_finite(b.joint.axis, "joint axis");
  }

  ffsr::Data work(model);
  const ffsr::Target target;  // the paper's
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(model.n());
  check_configuration(model, work, ffsr::BasePose{}, theta, model.end_effector(), target);

  // Pseudo-random configurations from a hash of the input (deterministic, so reproducible).
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  auto next = [&h] {  // uniform in [-1, 1)
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
  };
  const int nframes = static_cast<int>(model.frames().size());
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < model.n(); ++j) {
      const ffsr::Joint& jt = model.joint(j);
      double q = 3.2 * next();
      if (std::isfinite(jt.lower) && std::isfinite(jt.upper))
        q = jt.lower + 0.5 * (next() + 1.0) * (jt.upper - jt.lower);
      theta(j) = q;
    }
    ffsr::BasePose base;
    base.position = ffsr::Vector3(next(), next(), next());
    base.orientation = ffsr::Quaternion(next(), next(), next(), next());
    if (base.orientation.norm() < 1e-3) base.orientation = ffsr::Quaternion::Identity();
    const int frame = static_cast<int>(h % static_cast<uint64_t>(nframes));
    check_configuration(model, work, base, theta, frame, target);
  }
}

}  // namespace ffsr_fuzz
