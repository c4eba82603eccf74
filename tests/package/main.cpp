// A consumer of the installed ffsr package. Builds the paper's planar 3-DOF robot in code
// (Table 2: base 500 kg; links of 1.4, 1.6 and 0.5 m, 5, 6 and 4 kg) and prints M_ie at [0, 90, -90] deg
// (paper: 5.817 kg). With FFSR_CONSUMER_URDF it also loads the same robot from a URDF string and
// with FFSR_CONSUMER_CVODE it runs the single-body CVODE contact, so each component's headers and
// link dependencies are exercised. Exit 0 when the numbers are finite and the two models agree.
#include <ffsr/ffsr.hpp>
#ifdef FFSR_CONSUMER_URDF
#include <ffsr/parsers/urdf.hpp>
#endif
#ifdef FFSR_CONSUMER_CVODE
#include <ffsr/simulate/single_body.hpp>
#endif

#include <cmath>
#include <cstdio>

namespace {

// A link along its x axis: mass, centre of mass at (cx, 0, 0), diagonal inertia (Table 2).
ffsr::Inertia link(double m, double cx, double ixx, double iyy_izz) {
  return {m, ffsr::Vector3(cx, 0, 0), ffsr::Vector3(ixx, iyy_izz, iyy_izz).asDiagonal()};
}

ffsr::Model paper_3dof() {
  using namespace ffsr;
  auto at = [](double x) { return Pose{Vector3(x, 0, 0), Matrix3::Identity()}; };
  return ModelBuilder("base", {500, Vector3::Zero(), 200 * Matrix3::Identity()})
      .add_joint("j1", JointType::Revolute, "base", at(0.6), Vector3::UnitZ(), "link1",
                 link(5, 0.7, 0.01, 0.82))
      .add_joint("j2", JointType::Revolute, "link1", at(1.4), Vector3::UnitZ(), "link2",
                 link(6, 0.8, 0.01, 1.28))
      .add_joint("j3", JointType::Revolute, "link2", at(1.6), Vector3::UnitZ(), "link3",
                 link(4, 0.25, 0.0, 0.09))
      .add_fixed("ee_joint", "link3", at(0.5), "ee", Inertia{})
      .build();
}

double m_ie(const ffsr::Model& model) {
  ffsr::Data data(model);
  const double deg = M_PI / 180;
  const Eigen::VectorXd theta = Eigen::Vector3d(0, 90 * deg, -90 * deg);
  const ffsr::Target target;  // m = 200 kg, I = diag(100), r_tp = [-0.25, 0.15, 0], u_n = x
  return ffsr::integrated_effective_mass(model, data, ffsr::BasePose{}, theta, model.frame_index("ee"),
                                         target);
}

}  // namespace

int main() {
  const ffsr::Model model = paper_3dof();
  const double M = m_ie(model);
  std::printf("ffsr consumer: 3-DOF robot built in code, M_ie at [0, 90, -90] deg = %.4f kg\n", M);
  bool ok = std::isfinite(M) && M > 0;
#ifdef FFSR_CONSUMER_URDF
  const char* urdf = R"(<robot name="r">
  <link name="base"><inertial><mass value="500"/><inertia ixx="200" iyy="200" izz="200" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link1"><inertial><origin xyz="0.7 0 0"/><mass value="5"/><inertia ixx="0.01" iyy="0.82" izz="0.82" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link2"><inertial><origin xyz="0.8 0 0"/><mass value="6"/><inertia ixx="0.01" iyy="1.28" izz="1.28" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link3"><inertial><origin xyz="0.25 0 0"/><mass value="4"/><inertia ixx="0" iyy="0.09" izz="0.09" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="ee"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="link1"/><origin xyz="0.6 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><parent link="link1"/><child link="link2"/><origin xyz="1.4 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="j3" type="continuous"><parent link="link2"/><child link="link3"/><origin xyz="1.6 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="ee_joint" type="fixed"><parent link="link3"/><child link="ee"/><origin xyz="0.5 0 0"/></joint>
</robot>)";
  const double M_urdf = m_ie(ffsr::model_from_urdf_string(urdf, "consumer"));
  std::printf("ffsr consumer: the same robot from URDF, M_ie = %.4f kg\n", M_urdf);
  ok = ok && std::abs(M_urdf - M) <= 1e-9 * M;
#endif
#ifdef FFSR_CONSUMER_CVODE
  const ffsr::AnyContactLaw law = ffsr::make_contact_law("herbert-mcwhannell", {1e9, 1.5, 0.9}, 0.2);
  const double f_max = ffsr::simulate_single_body(law, M).f_max;
  std::printf("ffsr consumer: single-body CVODE contact at that M_ie, F_max = %.1f N\n", f_max);
  ok = ok && std::isfinite(f_max) && f_max > 0;
#endif
  return ok ? 0 : 1;
}
