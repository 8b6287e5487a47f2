// `dump ID group mesh/stl N file [all] [mesh-IDs ...]` (LIGGGHTS syntax): the
// current triangles of fix mesh/surface walls as an ASCII STL file, one solid
// per mesh (named by the fix ID), facet normals from the current geometry.
// A '*' in the file name is replaced by the step (one file per frame, as
// LIGGGHTS does); without '*' each frame overwrites the file. Meshes are
// replicated on every rank, so rank 0 writes the whole frame, to a temporary
// name renamed at the end (no half-written file is left behind). The group is
// ignored. See doc/commands/dump.md.
#include <cerrno>
#include <cstdio>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix_mesh_surface.h"
#include "core/modify.h"
#include "output/dump.h"
#include "output/dump_custom.h"

namespace granary {

namespace {

class DumpMeshSTL : public Dump {
 public:
  DumpMeshSTL(Engine& engine, const Args& args) : Dump(engine, args) {
    const std::string where = "dump " + id + " mesh/stl";
    if (filename.find('%') != std::string::npos)
      throw InputError(
          where + ": writes one file per frame on rank 0; '%' (one file per rank) is not supported in '" +
          filename + "'");
    for (std::size_t k = 5; k < args.size(); ++k) {
      const std::string& w = args[k];
      if (w == "all") continue;  // the whole mesh (every mesh is replicated)
      if (w == "local" || w == "ghost" || w == "region") {
        throw InputError(where + ": '" + w +
                         "' (per-processor parts of the mesh) is not supported; Granary writes whole meshes");
      }
      if (!engine.modify->find_fix(w)) {
        throw InputError(where + ": '" + w + "' is not the ID of a fix mesh/surface; usage: dump ID group " +
                         "mesh/stl N file [mesh-IDs ...]");
      }
      FixMeshSurface::find(*engine.modify, w, where);
      mesh_ids_.push_back(w);
    }
    dumpio::check_directory(engine.world, filename, "dump " + id);
  }

  int modify_param(const Args& args, std::size_t k) override {
    if (args[k] == "pad" && k + 1 < args.size()) {
      pad_ = static_cast<int>(parse_int(args[k + 1], "dump_modify " + id + " pad"));
      if (pad_ < 0) throw InputError("dump_modify " + id + " pad: must be >= 0");
      return 2;
    }
    return 0;
  }

  void init() override {
    if (meshes().empty()) throw InputError("dump " + id + " mesh/stl: there is no fix mesh/surface to write");
  }

  void write() override {
    std::string err;
    if (engine_.rank == 0) err = write_frame(dumpio::expand(filename, engine_.update->ntimestep, pad_));
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  std::vector<FixMeshSurface*> meshes() const {
    return FixMeshSurface::select(*engine_.modify, mesh_ids_, "dump " + id + " mesh/stl");
  }

  std::string write_frame(const std::string& file) const {
    return replace_file(file, [&](std::FILE* fp) {
      for (const FixMeshSurface* m : meshes()) {
        const TriMesh& mesh = m->mesh;
        std::fprintf(fp, "solid %s\n", m->id.c_str());
        for (int t = 0; t < mesh.ntri(); ++t) {
          const Vec3& n = mesh.normal(t);
          std::fprintf(fp, "  facet normal %.17g %.17g %.17g\n    outer loop\n", n[0], n[1], n[2]);
          for (int c = 0; c < 3; ++c) {
            const Vec3& p = mesh.corner(t, c);
            std::fprintf(fp, "      vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
          }
          std::fprintf(fp, "    endloop\n  endfacet\n");
        }
        std::fprintf(fp, "endsolid %s\n", m->id.c_str());
      }
    });
  }

  std::vector<std::string> mesh_ids_;
  int pad_ = 0;
};

}  // namespace

GRANARY_DUMP_STYLE("mesh/stl", DumpMeshSTL);

}  // namespace granary
