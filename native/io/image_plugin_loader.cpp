// io/image_plugin_loader.cpp — finds, checks and calls the image plugin.
#include "io/image_plugin_loader.h"

#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>

#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/image_plugin.h"

namespace cgio {

namespace {

struct Plugin {
  CloudgenWriteSliceFn write_slice = nullptr;
  std::string error;  // why it could not be loaded
};

std::string executable_dir() {
  char buf[PATH_MAX + 1];
  const ssize_t n = ::readlink("/proc/self/exe", buf, PATH_MAX);
  if (n <= 0)
    throw IoError(std::string("cannot find the cloudgen executable (/proc/self/exe): ") + std::strerror(errno));
  const std::string exe(buf, std::size_t(n));
  const auto slash = exe.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : exe.substr(0, slash);
}

Plugin open_plugin() {
  Plugin p;
  const std::string path = image_plugin_path();
  const std::string why = "cannot write PNG/EXR previews: the image plugin " + path;
  if (::access(path.c_str(), F_OK) != 0) {
    p.error = why +
              " is missing (it is built with the CLI, target cloudgen_image, and must stay in lib/ beside the "
              "directory of the cloudgen executable; bake, merge and info do not need it)";
    return p;
  }
  // Never closed: OpenImageIO keeps threads and static state until exit.
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* e = ::dlerror();
    p.error = why + " cannot be loaded: " + (e ? e : "unknown error");
    return p;
  }
  const auto id = reinterpret_cast<CloudgenImagePluginIdFn>(::dlsym(handle, CLOUDGEN_IMAGE_PLUGIN_ID_SYMBOL));
  const std::string want = "cloudgen-image " + std::to_string(CLOUDGEN_IMAGE_PLUGIN_ABI) + " " + cg::version();
  const std::string have = id ? std::string(id()) : std::string("no ") + CLOUDGEN_IMAGE_PLUGIN_ID_SYMBOL;
  if (have != want) {
    p.error = why + " belongs to another build ('" + have.substr(0, 100) + "', this cloudgen needs '" + want +
              "'); rebuild the CLI and its plugin together";
    return p;
  }
  p.write_slice = reinterpret_cast<CloudgenWriteSliceFn>(::dlsym(handle, CLOUDGEN_WRITE_SLICE_SYMBOL));
  if (!p.write_slice) p.error = why + " has no " + CLOUDGEN_WRITE_SLICE_SYMBOL;
  return p;
}

const Plugin& plugin() {
  static std::once_flag once;
  static Plugin p;
  std::call_once(once, [] { p = open_plugin(); });
  return p;
}

}  // namespace

std::string image_plugin_path() { return executable_dir() + "/../lib/cloudgen_image.so"; }

void load_image_plugin() {
  if (const Plugin& p = plugin(); !p.write_slice) throw IoError(p.error);
}

void write_slice_with_plugin(const std::string& path, ImageFormat format, const std::vector<float>& values, int width,
                             int height, const SliceMeta& meta) {
  load_image_plugin();
  if (width < 1 || height < 1 || values.size() != std::size_t(width) * std::size_t(height))
    throw IoError("cannot write '" + path + "': image size does not match its pixels");
  CloudgenImageSlice s{};
  s.path = path.c_str();
  s.format = format == ImageFormat::Png ? 0 : 1;
  s.values = values.data();
  s.width = width;
  s.height = height;
  s.params_json = meta.params_json.c_str();
  s.axis = meta.axis;
  s.offset = meta.offset;
  s.png_scale = meta.png_scale;
  char error[1024] = {0};
  if (plugin().write_slice(&s, error, sizeof error) != 0)
    throw IoError(error[0] ? error : ("cannot write '" + path + "': the image plugin failed"));
}

}  // namespace cgio
