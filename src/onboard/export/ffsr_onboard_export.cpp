// ffsr-onboard-export: a scenario's controller set-up as an onboard blob, written as C99 source for a
// flight program to compile in (include/ffsr/onboard.h reads it at start-up).
//
//   ffsr-onboard-export SCENARIO.toml capture|detumble NAME OUTPUT.c
//
// capture: the paper's method (the gradient policy) on the scenario's problem, task and options (the
// optimized run's); detumble: the detumbling controller on the stack the detumble job grasps at the
// scenario's start configuration, under its Detumble keys, from the stack's state after the grasp.
// The file is written only when the whole blob was made and read back (its controller built).
#include "ffsr/control/onboard_blob.hpp"
#include "ffsr/jobs/detumble.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <cstdio>
#include <exception>
#include <fstream>
#include <regex>
#include <string>

namespace {

std::vector<double> capture_of(const ffsr::Scenario& sc) {
  if (sc.geometry) throw ffsr::InputError("capture: a scenario with shapes and clearances: the clearance barrier does not go onboard");
  ffsr::CaptureOptions opt = sc.capture;
  opt.hold_base_attitude = sc.hold_base_attitude;
  opt.progress = nullptr;
  opt.record_series = false;
  return ffsr::capture_blob(sc.problem, sc.task, opt);
}

std::vector<double> detumble_of(const ffsr::Scenario& sc) {
  const ffsr::DetumbleJobResult d = ffsr::detumble(sc);
  const ffsr::Model& model = *sc.model;
  const int ee = sc.problem.frame;
  const ffsr::Model stack = ffsr::attach_body(model, model.frame(ee).name, d.grasp.body);
  const ffsr::DetumbleSettings& s = d.settings;
  return ffsr::detumble_blob(stack, ee, d.grasp.body, s.limits, s.options, s.run.tick, d.start);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: ffsr-onboard-export SCENARIO.toml capture|detumble NAME OUTPUT.c\n");
    return 2;
  }
  const std::string path = argv[1], kind = argv[2], name = argv[3], output = argv[4];
  if (kind != "capture" && kind != "detumble") {
    std::fprintf(stderr, "ffsr-onboard-export: the controller must be capture or detumble, got '%s'\n", argv[2]);
    return 2;
  }
  if (!std::regex_match(name, std::regex("[A-Za-z_][A-Za-z0-9_]*"))) {
    std::fprintf(stderr, "ffsr-onboard-export: NAME must be a C identifier, got '%s'\n", argv[3]);
    return 2;
  }
  try {
    const ffsr::Scenario sc = ffsr::load_scenario(path);
    const std::vector<double> blob = kind == "capture" ? capture_of(sc) : detumble_of(sc);
    const std::string text =
        ffsr::blob_c_source(blob, name, "the " + kind + " controller of " + path);
    const std::string partial = output + ".partial";
    {
      std::ofstream f(partial, std::ios::binary);
      f << text;
      if (!(f.flush())) throw ffsr::InputError("OUTPUT: cannot write " + output);
    }
    if (std::rename(partial.c_str(), output.c_str()) != 0) {
      std::remove(partial.c_str());
      throw ffsr::InputError("OUTPUT: cannot write " + output);
    }
    std::printf("%s: %zu doubles (%s controller of %s)\n", output.c_str(), blob.size(), kind.c_str(), path.c_str());
  } catch (const ffsr::InputError& e) {
    std::fprintf(stderr, "ffsr-onboard-export: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-onboard-export: %s\n", e.what());
    return 3;
  }
  return 0;
}
