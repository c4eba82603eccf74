// ffsr/contact/damping.hpp -- the hysteresis damping factors of Table 1 as compile-time policies.
#pragma once

#include <cmath>
#include <string_view>

// Every classical damping factor of Table 1 (Zhang et al. 2022, Aerospace 9, 69) has the form
// of Eq. 22,
//     λ = f(c_r) · K / δ̇⁻,
// so a policy is a stable lower-case name and the dimensionless factor f(c_r). Each f is zero at
// c_r = 1 (no damping) and positive for 0 < c_r < 1. The arguments are not validated here:
// ContactParams (contact_law.hpp) checks 0 < c_r <= 1 before any factor is evaluated.
//
// Adding a law: one struct here with `name` and `factor`, one entry in AnyContactLaw.

namespace ffsr {

/// Hunt-Crossley (Table 1): f = 3(1 - c_r)/2.
struct HuntCrossley {
  static constexpr std::string_view name = "hunt-crossley";
  static double factor(double c_r) { return 3.0 * (1.0 - c_r) / 2.0; }
};

/// Herbert-McWhannell (Table 1): f = 6(1 - c_r) / ((2c_r - 1)^2 + 3).
struct HerbertMcWhannell {
  static constexpr std::string_view name = "herbert-mcwhannell";
  static double factor(double c_r) {
    const double d = 2.0 * c_r - 1.0;
    return 6.0 * (1.0 - c_r) / (d * d + 3.0);
  }
};

/// Lankarani-Nikravesh (Table 1): f = 3(1 - c_r^2)/4.
struct LankaraniNikravesh {
  static constexpr std::string_view name = "lankarani-nikravesh";
  static double factor(double c_r) { return 3.0 * (1.0 - c_r) * (1.0 + c_r) / 4.0; }
};

/// Lee-Wang (Table 1): f = 3(1 - c_r)/4.
struct LeeWang {
  static constexpr std::string_view name = "lee-wang";
  static double factor(double c_r) { return 3.0 * (1.0 - c_r) / 4.0; }
};

/// Flores et al. (Table 1): f = 8(1 - c_r)/(5 c_r).
struct Flores {
  static constexpr std::string_view name = "flores";
  static double factor(double c_r) { return 8.0 * (1.0 - c_r) / (5.0 * c_r); }
};

/// Gonthier et al. (Table 1): f = (1 - c_r^2)/c_r.
struct Gonthier {
  static constexpr std::string_view name = "gonthier";
  static double factor(double c_r) { return (1.0 - c_r) * (1.0 + c_r) / c_r; }
};

/// Zhiying-Qishao (Table 1): f = 3(1 - c_r^2) e^{2(1 - c_r)} / 4.
struct ZhiyingQishao {
  static constexpr std::string_view name = "zhiying-qishao";
  static double factor(double c_r) {
    return 3.0 * (1.0 - c_r) * (1.0 + c_r) * std::exp(2.0 * (1.0 - c_r)) / 4.0;
  }
};

/// Hu-Guo (Table 1): f = 3(1 - c_r)/(2 c_r).
struct HuGuo {
  static constexpr std::string_view name = "hu-guo";
  static double factor(double c_r) { return 3.0 * (1.0 - c_r) / (2.0 * c_r); }
};

}  // namespace ffsr
