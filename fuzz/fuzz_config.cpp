// Config files (`run --config`, `batch --config`) as `run` takes them: apply_config_file, then
// validate, then the parameters as report.json lists them, which must be JSON. Built twice,
// with GT_FUZZ_EXT ".yaml" (yaml-cpp) and ".json" (nlohmann), since the extension picks the
// parser and a corpus file should be a config file as it is.

#include <cstddef>
#include <cstdint>
#include <groovetrace/config.hpp>
#include <groovetrace/pipeline.hpp>
#include <nlohmann/json.hpp>

#include "fuzz_support.hpp"

#ifndef GT_FUZZ_EXT
#error "build with -DGT_FUZZ_EXT=\".yaml\" or \".json\""
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = groovetrace::fuzz::write_input("params" GT_FUZZ_EXT, data, size);
  groovetrace::Params params;
  groovetrace::fuzz::expect_answer([&] {
    groovetrace::apply_config_file(params, path);
    groovetrace::validate(params);
  });
  // Whatever the file set before any error is what a run would report.
  std::string json;
  try {
    json = groovetrace::params_json(params);
    (void)nlohmann::json::parse(json);
  } catch (const std::exception& e) {
    groovetrace::fuzz::finding(std::string("the parameters are not JSON: ") + e.what());
  }
  return 0;
}
