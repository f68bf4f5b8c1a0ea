// fuzz_camera.cpp — libFuzzer target: camera files (cg::parse_camera), and the
// fit of an accepted camera to the default cloud box (cg::fit_camera).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "cloudgen/camera.h"
#include "cloudgen/model.h"
#include "cloudgen/params.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const cg::CameraView c = cg::parse_camera(text, "fuzz");
    static const cg::Model model = cg::prepare(cg::Params());
    const cg::CameraFit fit = cg::fit_camera(model, c);
    if (fit.visible && !(fit.voxel >= 0.0f)) std::abort();  // never NaN or negative
  } catch (const cg::ParamError& e) {
    if (e.message.size() > 1000) std::abort();
  }
  return 0;
}
