// python/src/common.hpp -- what every source of the extension ffsr._ffsr includes first: the library's
// headers, nanobind, the namespace alias and the Python-side types that are not library types.
#pragma once

#include "ffsr/ffsr.hpp"
#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/contact/contact_law.hpp"

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

namespace ffsr::python {

namespace nb = nanobind;

/// A contact law chosen by name (AnyContactLaw), as the Python class ffsr.ContactLaw.
struct ContactLaw {
  AnyContactLaw law;
};

}  // namespace ffsr::python
