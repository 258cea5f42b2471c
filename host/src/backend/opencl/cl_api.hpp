#pragma once
// The Khronos C++ bindings, configured once for every OpenCL source of the library: OpenCL 1.2
// API (set by CMake), errors as cl::Error exceptions (converted to OpenClError at the backend
// boundary). Included as a system header: its own warnings are not ours to fix.
#ifndef CL_HPP_ENABLE_EXCEPTIONS
#define CL_HPP_ENABLE_EXCEPTIONS
#endif
#pragma GCC system_header
#if __has_include(<CL/opencl.hpp>)
#include <CL/opencl.hpp>
#else
#include <CL/cl2.hpp>
#endif

#include <string>

namespace groovetrace::ocl {

/// Symbolic name of an OpenCL status code, e.g. "CL_OUT_OF_RESOURCES".
const char* status_name(int status);

}  // namespace groovetrace::ocl
