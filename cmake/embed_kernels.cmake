# Writes OUT (C++) holding each OpenCL source in KERNELS (|-separated paths) as a raw string,
# looked up by file name through groovetrace::embedded_kernel(name). Run with cmake -P.
set(body "// Generated from kernels/*.cl by cmake/embed_kernels.cmake. Do not edit.\n")
string(APPEND body "#include <cstring>\n\nnamespace groovetrace {\n\nconst char* embedded_kernel([[maybe_unused]] const char* name) {\n")
string(REPLACE "|" ";" KERNELS "${KERNELS}")
foreach(path ${KERNELS})
  get_filename_component(name ${path} NAME)
  file(READ ${path} src)
  string(APPEND body "  if (std::strcmp(name, \"${name}\") == 0) return R\"GTCL(${src})GTCL\";\n")
endforeach()
string(APPEND body "  return nullptr;\n}\n\n}  // namespace groovetrace\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
