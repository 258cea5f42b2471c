// Calibration files (`--hand-eye`, `--flange-pose`, a manifest's poses) through read_transform.
// Built twice, with GT_FUZZ_EXT ".yaml" and ".json", since the extension picks the parser.
// A transform it returns must be rigid and finite (frames.hpp).

#include <cstddef>
#include <cstdint>
#include <groovetrace/frames.hpp>

#include "fuzz_support.hpp"

#ifndef GT_FUZZ_EXT
#error "build with -DGT_FUZZ_EXT=\".yaml\" or \".json\""
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = groovetrace::fuzz::write_input("transform" GT_FUZZ_EXT, data, size);
  groovetrace::fuzz::expect_answer([&] {
    const Eigen::Isometry3d T = groovetrace::read_transform(path);
    const Eigen::Matrix3d R = T.linear();
    groovetrace::fuzz::require(T.matrix().allFinite(), "the transform is finite");
    groovetrace::fuzz::require(
        (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 && R.determinant() > 0,
        "the rotation is a rotation");
  });
  return 0;
}
