// python/src/outputs.cpp -- numpy arrays out of ffsr._ffsr (outputs.hpp).
#include "outputs.hpp"

namespace ffsr::python {

ArrayOut view(const Eigen::MatrixXd& m, nb::handle owner) {
  const size_t shape[2] = {static_cast<size_t>(m.rows()), static_cast<size_t>(m.cols())};
  const int64_t strides[2] = {1, m.rows()};  // Eigen's column-major storage
  return ArrayOut(m.data(), 2, shape, owner, strides);
}

ArrayOut view(const Eigen::VectorXd& v, nb::handle owner) {
  const size_t shape[1] = {static_cast<size_t>(v.size())};
  return ArrayOut(v.data(), 1, shape, owner);
}

NewArray copy_out(const Eigen::Ref<const Eigen::MatrixXd>& m, bool as_vector) {
  const auto r = static_cast<size_t>(m.rows()), c = static_cast<size_t>(m.cols());
  auto* buf = new double[r * c];
  for (size_t i = 0; i < r; ++i)
    for (size_t j = 0; j < c; ++j) buf[i * c + j] = m(Eigen::Index(i), Eigen::Index(j));  // C order
  nb::capsule owner(buf, [](void* p) noexcept { delete[] static_cast<double*>(p); });
  const size_t shape[2] = {r, c};
  const size_t vshape[1] = {r * c};
  return as_vector ? NewArray(buf, 1, vshape, owner) : NewArray(buf, 2, shape, owner);
}

NewArray new_array(size_t n, double** data) {
  auto* buf = new double[n];
  nb::capsule owner(buf, [](void* p) noexcept { delete[] static_cast<double*>(p); });
  *data = buf;
  const size_t shape[1] = {n};
  return NewArray(buf, 1, shape, owner);
}

NewArray array_of(const std::vector<double>& v) {
  return out(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()))));
}

NewArray out_quat(const Quaternion& q) {
  return copy_out(q.coeffs(), true);  // x, y, z, w
}

nb::object json_loads(const std::string& text) {
  return nb::module_::import_("json").attr("loads")(nb::str(text.data(), text.size()));
}

}  // namespace ffsr::python
