// Methods written in Python, registered into the method registry (python/python_method.cpp).
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace geomint {

// Adds register_method, python_methods, check_names and check to the extension module.
void bind_python_methods(pybind11::module_& module);
// A Python method's summary as last registered (a name registered again keeps its registry
// entry); `registry_summary` for every other method.
std::string python_method_summary(const std::string& name, const std::string& registry_summary);

}  // namespace geomint
