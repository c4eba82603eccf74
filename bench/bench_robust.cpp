// bench/bench_robust.cpp -- ffsr-bench-robust: the Monte Carlo of uncertain targets on the 7-DOF robot.
#include "ffsr/detail/parallel.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/uncertainty/multibody.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

//   ffsr-bench-robust [--quick] [DIR]
//
// Times (steady_clock, wall) drawing and evaluating 1e5 samples with the exact single-body F_max,
// and 1e3 samples with the multibody CVODE model, both on 2 threads, with the spreads of
// robots/paper_7dof_position_uncertain.toml around the paper's 7-DOF position scenario at the
// capture configuration given below, the percentiles conditional on the stiffness as the CLI computes
// them (summary included in the time). Targets: < 2 s and < 30 s on 2 cores. Then the
// scatter of the p95 from disjoint blocks of 1000 samples, both estimators. --quick:
// 1e4 and 20 samples (a smoke run). DIR holds paper_7dof.urdf (default FFSR_SOURCE_DIR/robots).

namespace {

using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point a) {
  return std::chrono::duration<double>(clock_type::now() - a).count();
}

/// The scenario's target, propagated to the capture time T = 157 s, and the paper's contact.
ffsr::UncertainNominal paper_nominal() {
  using namespace ffsr;
  Target t0;
  t0.mass = 200;
  t0.inertia = 100 * Matrix3::Identity();
  t0.position = Vector3(2.3, -0.8, 2);
  t0.angular_velocity = Vector3(1, -0.5, 2) * (M_PI / 180);
  t0.contact_offset = Vector3(-0.25, 0.15, 0.1);
  return UncertainNominal{propagate_target(t0, 157.0), {1e9, 1.5, 0.9}, 0.2};
}

/// The spreads of robots/paper_7dof_position_uncertain.toml.
ffsr::UncertaintySpec paper_spreads() {
  using namespace ffsr;
  UncertaintySpec spec;
  spec.seed = 2022;
  auto uniform_rel = [](double r) {
    Spread s;
    s.law = Spread::Law::Uniform;
    s.scale = r;
    s.relative = true;
    return s;
  };
  spec[Quantity::TargetMass] = uniform_rel(0.1);
  spec[Quantity::TargetInertia] = uniform_rel(0.2);
  spec[Quantity::ContactOffset].law = Spread::Law::Uniform;
  spec[Quantity::ContactOffset].scale = 0.02;
  spec[Quantity::ContactPoint].law = Spread::Law::Uniform;  // the example scenario's table
  spec[Quantity::ContactPoint].scale = 0.05;
  spec[Quantity::Normal].law = Spread::Law::Cone;
  spec[Quantity::Normal].scale = 5 * M_PI / 180;
  spec[Quantity::Spin].law = Spread::Law::Normal;
  spec[Quantity::Spin].scale = 0.2 * M_PI / 180;
  spec[Quantity::Restitution].law = Spread::Law::Uniform;
  spec[Quantity::Restitution].has_range = true;
  spec[Quantity::Restitution].min = 0.6;
  spec[Quantity::Restitution].max = 0.95;
  spec[Quantity::Stiffness].law = Spread::Law::LogNormal;
  spec[Quantity::Stiffness].scale = 0.587;
  validate(spec);
  return spec;
}

/// The exact single-body forces of the samples and their stiffness-conditional summary.
struct ExactRun {
  std::vector<ffsr::UncertainSample> samples;
  std::vector<double> f, K, alpha;
  ffsr::ForceSummary summary;
};

/// Convergence: disjoint blocks of 1000 of the samples, each block's p95 against the whole set's,
/// for the two estimators (the aim: 1e3 against 1e5 within 1 %).
void print_block_scatter(const ExactRun& run, const ffsr::Spread& k_law, double K0) {
  const std::size_t n = run.f.size(), block = 1000, blocks = n / block;
  double sc = 0, sc2 = 0, so = 0, so2 = 0;
  int within_c = 0, within_o = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    auto cut = [&](const std::vector<double>& v) {
      return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(b * block),
                                 v.begin() + static_cast<std::ptrdiff_t>((b + 1) * block));
    };
    const ffsr::ForceSummary sb =
        summarize_stiffness_conditional(cut(run.f), cut(run.K), cut(run.alpha), k_law, K0);
    const double ec = sb.p95 / run.summary.p95 - 1, eo = sb.order.p95 / run.summary.order.p95 - 1;
    sc += ec;
    sc2 += ec * ec;
    so += eo;
    so2 += eo * eo;
    within_c += std::abs(ec) < 0.01;
    within_o += std::abs(eo) < 0.01;
  }
  const double nb = static_cast<double>(blocks);
  auto sd = [nb](double a, double a2) { return std::sqrt(std::max(0.0, a2 / nb - (a / nb) * (a / nb))); };
  std::printf(
      "p95 of %zu blocks of 1000 against all %llu samples: stiffness-conditional sd %.2f %%, %d within 1 "
      "%%;"
      " order statistics sd %.2f %%, %d within 1 %%\n",
      blocks, static_cast<unsigned long long>(n), 100 * sd(sc, sc2), within_c, 100 * sd(so, so2), within_o);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace ffsr;
  bool quick = false;
  std::string dir = std::string(FFSR_SOURCE_DIR) + "/robots";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else
      dir = a;
  }
  try {
    const Model model = model_from_urdf_file(dir + "/paper_7dof.urdf", "ee");
    const int frame = model.end_effector();
    Eigen::VectorXd theta(7);
    theta << 5, 80, 95, -85, 92, 88, 3;
    theta *= M_PI / 180.0;
    const BasePose base;
    const UncertainNominal nominal = paper_nominal();
    const UncertaintySpec spec = paper_spreads();
    const std::string law = "herbert-mcwhannell";

    const std::uint64_t n_exact = quick ? 10000 : 100000, n_mb = quick ? 20 : 1000;
    auto t = clock_type::now();
    ExactRun run;
    run.samples.resize(n_exact);
    run.f.resize(n_exact);
    Data data(model);
    const Matrix6 G = robot_inverse_inertia(model, data, base, theta, frame);
    detail::parallel_for(n_exact, 2, [&](std::uint64_t i) {
      run.samples[i] = draw_sample(spec, nominal, i);
      run.f[i] = sample_force(G, run.samples[i], law, ForceModel::Exact).f_max;
    });
    for (std::uint64_t i = 0; i < n_exact; ++i) {
      run.K.push_back(run.samples[i].contact.K);
      run.alpha.push_back(run.samples[i].contact.alpha);
    }
    const Spread& k_law = spec[Quantity::Stiffness];
    run.summary = summarize_stiffness_conditional(run.f, run.K, run.alpha, k_law, nominal.contact.K);
    const double t_exact = seconds_since(t);
    std::printf(
        "exact F_max:     %7llu samples in %7.3f s on 2 threads (target < 2 s for 1e5)   p95 %.1f N"
        " (order statistic %.1f N)\n",
        static_cast<unsigned long long>(n_exact), t_exact, run.summary.p95, run.summary.order.p95);
    print_block_scatter(run, k_law, nominal.contact.K);
    t = clock_type::now();
    std::vector<double> fm(n_mb);
    detail::parallel_for(n_mb, 2, [&](std::uint64_t i) {
      fm[i] = sample_force_multibody(model, base, theta, frame, run.samples[i], law).f_max;
    });
    const double t_mb = seconds_since(t);
    double worst = 0;
    for (std::uint64_t i = 0; i < n_mb; ++i) worst = std::max(worst, std::abs(fm[i] / run.f[i] - 1));
    std::printf(
        "multibody F_max: %7llu samples in %7.3f s on 2 threads (target < 30 s for 1e3)  largest |mb/exact - "
        "1| %.3g\n",
        static_cast<unsigned long long>(n_mb), t_mb, worst);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench-robust: %s\n", e.what());
    return 1;
  }
}
