// OpenCL device discovery and choice, the per-process program cache, the typed build error
// with its log, and the auto backend's fallback. Skipped when no OpenCL device exists.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>

#include "support/opencl_support.hpp"

namespace groovetrace {
namespace {

#define REQUIRE_DEVICES(devices)              \
  const auto devices = list_opencl_devices(); \
  if (devices.empty()) GTEST_SKIP() << "no OpenCL device on this machine"

TEST(OpenClDevice, ListsDevicesWithNamesAndTypes) {
  REQUIRE_DEVICES(devices);
  for (std::size_t k = 0; k < devices.size(); ++k) {
    EXPECT_EQ(devices[k].index, static_cast<int>(k));
    EXPECT_FALSE(devices[k].name.empty());
    EXPECT_FALSE(devices[k].platform.empty());
    EXPECT_NE(devices[k].type, "");
    EXPECT_GT(devices[k].compute_units, 0u);
  }
}

TEST(OpenClDevice, SelectsByIndexAndByNameAndRefusesUnknownOnes) {
  REQUIRE_DEVICES(devices);
  auto first = make_opencl_backend("0");
  EXPECT_EQ(first->name(), "opencl");
  EXPECT_NE(first->device().find(devices[0].name), std::string::npos);
  // A case-changed part of the platform name selects too.
  std::string part = devices[0].platform.substr(0, 6);
  std::transform(part.begin(), part.end(), part.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  EXPECT_NE(make_opencl_backend(part)->device().find(devices[0].name), std::string::npos);
  EXPECT_THROW(make_opencl_backend(std::to_string(devices.size())), UsageError);
  EXPECT_THROW(make_opencl_backend("no such device anywhere"), UsageError);
  EXPECT_THROW(make_backend("opencl", "no such device anywhere"), UsageError);
  EXPECT_THROW(make_backend("auto", "no such device anywhere"), UsageError);
}

TEST(OpenClDevice, FactoryNamesTheBackendAndDevice) {
  REQUIRE_DEVICES(devices);
  auto a = make_backend("auto");
  EXPECT_EQ(a->name(), "opencl");  // the default path wherever a device exists
  EXPECT_TRUE(a->warning().empty());
  EXPECT_FALSE(a->device().empty());
  EXPECT_EQ(make_backend("opencl", "0")->name(), "opencl");
  EXPECT_EQ(make_backend("cpu", "0")->name(), "cpu");
}

TEST(OpenClDevice, ProgramIsBuiltOncePerDevice) {
  REQUIRE_DEVICES(devices);
  auto warm = make_opencl_backend();
  const std::size_t builds = opencl_program_builds();
  Cloud c;
  c.x = {0, 0.001f, 0, 0.001f};
  c.y = {0, 0, 0.001f, 0.001f};
  c.z = {0.4f, 0.4f, 0.4f, 0.401f};
  c.width = 4;
  for (int k = 0; k < 3; ++k) {
    auto b = make_opencl_backend();
    b->normals(c, 0.003f, 3);
  }
  EXPECT_EQ(opencl_program_builds(), builds);
}

// A kernel that does not compile: the error is typed, names the device, and carries the
// compiler's log; "auto" falls back to the CPU and says why.
TEST(OpenClDevice, BuildFailureCarriesTheLogAndAutoFallsBack) {
  REQUIRE_DEVICES(devices);
  const test::ScopedEnv bad("GROOVETRACE_OPENCL_OPTIONS",
                            "-DVW=3");  // kernels/common.cl refuses it
  try {
    make_opencl_backend();
    FAIL() << "the build should fail";
  } catch (const OpenClError& e) {
    EXPECT_EQ(e.code(), ExitCode::kInternal);
    EXPECT_NE(std::string(e.what()).find("failed to build"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "what() is one line";
    EXPECT_NE(e.build_log().find("VW must be"), std::string::npos) << e.build_log();
  }
  auto fallback = make_backend("auto");
  EXPECT_EQ(fallback->name(), "cpu");
  EXPECT_NE(fallback->warning().find("failed to build"), std::string::npos);
  EXPECT_THROW(make_backend("opencl"), OpenClError);
}

}  // namespace
}  // namespace groovetrace
