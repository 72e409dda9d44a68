// quadlod — one libFuzzer driver, built once per target with QUADLOD_FUZZ_TARGET set to
// obj / ply / off / pipeline (fuzz/CMakeLists.txt). A broken property aborts so that libFuzzer
// saves the input as a finding; `scripts/fuzz` runs every target.
#include "fuzz_checks.h"

#include <cstdio>
#include <cstdlib>
#include <string_view>

#define QUADLOD_FUZZ_STR2(x) #x
#define QUADLOD_FUZZ_STR(x) QUADLOD_FUZZ_STR2(x)

namespace {

std::string run(std::string_view target, std::string_view bytes) {
  using namespace quadlod;
  if (target == "obj") return fuzz::check_reader(MeshFormat::Obj, bytes);
  if (target == "ply") return fuzz::check_reader(MeshFormat::Ply, bytes);
  if (target == "off") return fuzz::check_reader(MeshFormat::Off, bytes);
  if (target == "pipeline") return fuzz::check_pipeline(bytes);
  if (target == "fbx_binary") return fuzz::check_fbx_binary(bytes);
#ifdef QUADLOD_FUZZ_HAS_SCENE
  // The assimp front end: glTF binary, the format with the largest parser surface of the three
  // quadlod writes (fuzz_assimp_dae / _fbx: same driver, other hints).
  if (target == "assimp") return fuzz::check_scene("glb", bytes);
  if (target == "assimp_dae") return fuzz::check_scene("dae", bytes);
  if (target == "assimp_fbx") return fuzz::check_scene("fbx", bytes);
#endif
  return "unknown fuzz target";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string_view target = QUADLOD_FUZZ_STR(QUADLOD_FUZZ_TARGET);
  const std::string problem = run(target, {reinterpret_cast<const char*>(data), size});
  if (!problem.empty()) {
    std::fprintf(stderr, "quadlod fuzz %s: %s\n", target.data(), problem.c_str());
    std::abort();
  }
  return 0;
}
