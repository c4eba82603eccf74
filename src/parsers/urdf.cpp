// src/parsers/urdf.cpp -- the entry points of the URDF loader (parsers/urdf.hpp), compiled once into the
// library of the CMake target ffsr::urdf. Their documentation is in parsers/urdf.hpp.
#include "ffsr/parsers/detail/urdf_document.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace ffsr {

Model model_from_urdf_string(const std::string& xml, const std::string& source, const UrdfOptions& opt,
                             UrdfReport* report) {
  const detail::UrdfDocument doc = detail::parse_urdf_document(xml, source);
  try {
    return detail::model_from_urdf_document(*doc.model, xml, source, opt, report);
  } catch (const ModelError& e) {
    throw ModelError(detail::str(source, ": ", e.what()));
  } catch (const InputError& e) {
    throw InputError(detail::str(source, ": ", e.what()));
  }
}

Model model_from_urdf_string(const std::string& xml, const std::string& source, const std::string& end_effector) {
  UrdfOptions opt;
  opt.end_effector = end_effector;
  return model_from_urdf_string(xml, source, opt);
}

Model model_from_urdf_file(const std::string& path, const UrdfOptions& opt, UrdfReport* report) {
  // Only regular files of a sane size: /dev/zero or a FIFO would be read forever.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status))
    throw ModelError(detail::str(path, ": cannot open the URDF file"));
  if (!std::filesystem::is_regular_file(status)) throw ModelError(detail::str(path, ": not a regular file"));
  const auto size = std::filesystem::file_size(path, ec);
  constexpr std::uintmax_t kMaxBytes = 64u << 20;
  if (ec || size > kMaxBytes) throw ModelError(detail::str(path, ": the URDF file is larger than 64 MiB"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError(detail::str(path, ": cannot open the URDF file"));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ModelError(detail::str(path, ": cannot read the URDF file"));
  return model_from_urdf_string(ss.str(), path, opt, report);
}

Model model_from_urdf_file(const std::string& path, const std::string& end_effector) {
  UrdfOptions opt;
  opt.end_effector = end_effector;
  return model_from_urdf_file(path, opt);
}

}  // namespace ffsr
