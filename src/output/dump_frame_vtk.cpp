#include "output/dump_frame_vtk.h"

#include "core/engine.h"
#include "core/error.h"
#include "output/dump_custom.h"

namespace granary {

FrameDumpVTK::FrameDumpVTK(Engine& engine, const Args& args, const std::string& style,
                           const std::string& xml_ext, const std::string& example)
    : Dump(engine, args) {
  const std::string where = "dump " + id + " " + style;
  const std::string ext = vtkio::extension(filename);
  if (ext != ".vtk" && ext != xml_ext)
    throw InputError(where + ": needs a file name ending in .vtk (legacy VTK) or " + xml_ext +
                     " (VTK XML), got '" + filename + "'; e.g. " + example);
  if (filename.find('%') != std::string::npos)
    throw InputError(where + ": writes one file per frame on rank 0; '%' is not allowed in '" + filename +
                     "'");
  dumpio::check_directory(engine.world, filename, "dump " + id);
  legacy_ = ext == ".vtk";
  if (!legacy_) pvd_.path = vtkio::pvd_name(filename, id);
}

void FrameDumpVTK::single_file() {
  pvd_.path.clear();
  pvd_.clear();
}

int FrameDumpVTK::modify_param(const Args& args, std::size_t k) {
  const std::string where = "dump_modify " + id + " " + args[k];
  if (const int used = options_.parse(args, k, where)) return used;
  if (const int used = dumpio::parse_pvd(engine_.world, args, k, where, legacy_, pvd_.path)) {
    pvd_.clear();
    return used;
  }
  return 0;
}

}  // namespace granary
