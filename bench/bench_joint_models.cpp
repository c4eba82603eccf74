// bench/bench_joint_models.cpp -- ffsr-bench-joint-models: the effective mass and its gradient under
// each joint model of the contact (free, locked, armature) on the paper's 7-DOF robot.
//
//   ffsr-bench-joint-models [--quick] [DIR]
//
// Times (steady_clock, wall, one thread) crba + the inverse effective mass, and the gradient of M_ie
// (crba included), per call, over random configurations. DIR holds paper_7dof.urdf (default
// FFSR_SOURCE_DIR/robots).
#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace ffsr;
  bool quick = false;
  std::string dir = std::string(FFSR_SOURCE_DIR) + "/robots";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0)
      quick = true;
    else
      dir = argv[i];
  }
  const Model model = model_from_urdf_file(dir + "/paper_7dof.urdf", "ee");
  Data data(model);
  const int n = model.n(), reps = quick ? 1000 : 200000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-2.5, 2.5);
  std::vector<Eigen::VectorXd> thetas(64, Eigen::VectorXd(n));
  for (auto& t : thetas)
    for (int k = 0; k < n; ++k) t(k) = U(rng);
  const BasePose base;
  const Vector3 u = Vector3(1, 0.5, -0.3).normalized();
  Eigen::VectorXd grad(n);
  std::printf("joint models on the 7-DOF robot, %d calls each (ns per call)\n", reps);
  std::printf("%-10s %14s %18s\n", "model", "crba + 1/m_e", "gradient of M_ie");
  for (JointModel m : {JointModel::Free, JointModel::Locked, JointModel::Armature}) {
    const ContactJoints joints{m, Eigen::VectorXd::Constant(n, 0.5)};
    double sink = 0;
    auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r) {
      crba(model, data, base, thetas[size_t(r) % thetas.size()]);
      sink += inverse_effective_mass(model, data, model.end_effector(), u, joints);
    }
    const double t_value =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r)
      sink += integrated_effective_mass_gradient_dense(model, data, base, thetas[size_t(r) % thetas.size()],
                                                       model.end_effector(), u, 0.01, joints, grad);
    const double t_grad =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%-10s %14.0f %18.0f   (checksum %.6g)\n", joint_model_name(m), t_value / reps, t_grad / reps,
                sink);
  }
  return 0;
}
