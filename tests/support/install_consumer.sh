#!/usr/bin/env bash
# Installs the built project into a temporary prefix and checks the installed package as a
# program outside this tree sees it:
#   - the package passes on no private dependency (PCL, VTK, MPI, OpenCL, OpenMP, yaml-cpp);
#   - every installed header compiles on its own against the package;
#   - the shared library exports the API and none of the internal stages;
#   - examples/consumer builds against the package only and finds the groove with both methods.
# Usage: install_consumer.sh BUILD_DIR SOURCE_DIR [SANITIZERS]
# SANITIZERS (GT_SANITIZE, e.g. address,undefined): the library was built with them, and a
# program linking it must be too (an uninstrumented program loads ASan's runtime too late).
set -euo pipefail
build=$1
src=$2
san_flags=()
if [ -n "${3:-}" ]; then
  san_flags=(-DCMAKE_CXX_FLAGS="-fsanitize=$3" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=$3")
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
lib=$(find "$work/prefix" -name 'libgroovetrace.so' | head -1)

# PCL (and the VTK and MPI it drags in), OpenCL, OpenMP and yaml-cpp stay private: no include
# directory, compile flag or link library of theirs reaches a consumer. (CMake still lists the
# private shared libraries under IMPORTED_LINK_DEPENDENT_LIBRARIES, a hint for the linker's
# -rpath-link that adds nothing to a consumer's command lines.)
if grep -rhE '^ *INTERFACE_' "$work"/prefix/lib*/cmake/groovetrace/ | grep -qiE 'pcl|vtk|mpi|opencl|openmp|yaml'; then
  echo "install: the CMake package passes a private dependency on" >&2
  exit 1
fi
if grep -rqE '#include <(pcl|CL|omp|yaml-cpp|nlohmann)' "$work"/prefix/include/groovetrace/; then
  echo "install: an installed header includes a private dependency" >&2
  exit 1
fi

# Each header alone, in a translation unit of its own, with only the package's flags.
mkdir -p "$work/headers"
for h in "$work"/prefix/include/groovetrace/*.hpp; do
  echo "#include <groovetrace/$(basename "$h")>" >"$work/headers/$(basename "$h" .hpp).cpp"
done
cat >"$work/headers/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.18)
project(headers LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(groovetrace 0.1 REQUIRED)
file(GLOB sources *.cpp)
add_library(headers OBJECT ${sources})
target_link_libraries(headers PRIVATE groovetrace::groovetrace)
CMAKE
cmake -S "$work/headers" -B "$work/headers/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/headers/build" >/dev/null

# Exported symbols: the API is there, internal stages are not.
symbols=$(nm -DC --defined-only "$lib")
for api in 'groovetrace::run_pipeline(' 'groovetrace::detect_robust(' 'groovetrace::read_cloud(' \
           'groovetrace::paper_trajectory(' 'groovetrace::make_backend(' 'groovetrace::version()'; do
  grep -qF "$api" <<<"$symbols" || { echo "install: $api is not exported" >&2; exit 1; }
done
for internal in 'crease_nodes(' 'fit_v_profile(' 'order_nodes(' 'smooth_curve(' 'NeighborGrid' \
                'smallest_eigenvector(' 'score_seam(' 'label_grooves(' 'crease_map('; do
  if grep -qF "$internal" <<<"$symbols"; then
    echo "install: internal $internal is exported" >&2
    exit 1
  fi
done
echo "install: $(grep -c 'groovetrace::' <<<"$symbols") groovetrace symbols exported"

cmake -S "$src/examples/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release "${san_flags[@]}" >/dev/null
cmake --build "$work/build" >/dev/null
LD_LIBRARY_PATH="$work/prefix/lib:$work/prefix/lib64:${LD_LIBRARY_PATH:-}" "$work/build/consumer"
