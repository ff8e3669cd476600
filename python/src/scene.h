// The scene readers' bindings (scene.cpp), added to the module by module.cpp.
#pragma once

#include <pybind11/pybind11.h>

namespace conus::python {

void addSceneReaders(pybind11::module_& m);

}  // namespace conus::python
