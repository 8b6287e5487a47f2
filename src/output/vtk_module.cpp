#include "output/vtk_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <memory>

#include "core/error.h"
#include "output/vtk_module_interface.h"

namespace granary {

const std::vector<std::string>& vtk_module_dump_styles() {
  // sorted by name, as DumpRegistry::names() lists them
  static const std::vector<std::string> names = {"atom/vtk",          "bodies/vtk", "custom/vtk",
                                                 "decomposition/vtk", "euler/vtk",  "local/gran/vtk",
                                                 "mesh/gran/VTK",     "mesh/vtk",   "mesh/vtm"};
  return names;
}

DumpRegistry& vtk_module_dumps() {
  static DumpRegistry registry;
  return registry;
}

namespace {

std::string loaded_path;

std::string executable_folder() {
  std::string buf(4096, '\0');
  const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n <= 0) return "";
  buf.resize(static_cast<std::size_t>(n));
  const auto slash = buf.rfind('/');
  return slash == std::string::npos ? std::string(".") : buf.substr(0, slash);
}

}  // namespace

const std::string& vtk_module_path() {
  return loaded_path;
}

void load_vtk_module(const std::string& style) {
  if (!loaded_path.empty()) return;
  const char* env = std::getenv("GRANARY_VTK_MODULE");
  const bool from_env = env && *env;
  const std::string path = from_env ? std::string(env) : executable_folder() + "/granary_vtk.so";
  const std::string where = from_env ? "(named by GRANARY_VTK_MODULE)" : "(beside the granary executable)";
  const std::string need = "dump style " + style + " is written by Granary's VTK module, ";
  if (access(path.c_str(), R_OK) != 0) {
    throw InputError(need + "which is not at " + path + " " + where +
                     ": keep granary_vtk.so of the same build in the folder of the granary executable "
                     "(copy both together), or name it with the environment variable GRANARY_VTK_MODULE");
  }
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw InputError(need + "which could not be loaded from " + path + ": " + (why ? why : "unknown error"));
  }
  using InterfaceFn = const char* (*)();
  auto iface = reinterpret_cast<InterfaceFn>(dlsym(handle, "granary_vtk_module_interface"));
  const std::string here = vtk_module_interface_here();
  if (!iface || here != iface()) {
    const std::string theirs = iface ? iface() : "no interface mark";
    // its registrations ran: drop them (their code is the module's) before unloading it
    vtk_module_dumps() = DumpRegistry();
    dlclose(handle);
    throw InputError(need + "but " + path + " belongs to another build (" + theirs +
                     "; this granary: " + here + "): use the granary_vtk.so built with this granary");
  }
  // exactly the styles the registry names (both lists sorted by name)
  if (vtk_module_dumps().names() != vtk_module_dump_styles()) {
    std::string provided;
    for (const std::string& name : vtk_module_dumps().names())
      provided += " " + name;
    throw InputError(need + "but " + path + " provides the dump styles" + provided +
                     ", not those of vtk_module_dump_styles() (src/output/vtk_module.cpp)");
  }
  loaded_path = path;  // never unloaded: its code runs until the program ends
}

namespace {

std::unique_ptr<Dump> create_from_module(const std::string& style, Engine& engine, const Args& args) {
  load_vtk_module(style);  // it provides every style of vtk_module_dump_styles()
  return (*vtk_module_dumps().find(style))(engine, args);
}

const bool registered = [] {
  for (const std::string& name : vtk_module_dump_styles()) {
    DumpRegistry::instance().add(name,
                                 [name](Engine& e, const Args& a) { return create_from_module(name, e, a); });
  }
  return true;
}();

}  // namespace

}  // namespace granary
