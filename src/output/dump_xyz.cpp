// `dump ID group xyz N file`: the XYZ format LIGGGHTS 3.8 writes, one frame
// per step: the particle count, the line "Atoms. Timestep: STEP", then
// "type x y z" per particle (%g; dump_modify format and precision apply, as
// do sort, pad, append and region). One file on rank 0, or one file per frame
// with '*' in the name. See doc/commands/dump.md.
#include <cinttypes>
#include <cstdio>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "output/dump_custom.h"

namespace granary {

namespace {

Args xyz_args(const Args& args) {
  if (args.size() != 5) {
    throw InputError("dump " + (args.empty() ? std::string("?") : args[0]) +
                     " xyz takes no fields (it writes type x y z); usage: dump ID group-ID xyz N file");
  }
  Args out(args);
  for (const char* f : {"type", "x", "y", "z"})
    out.emplace_back(f);
  return out;
}

class DumpXYZ : public DumpCustom {
 public:
  DumpXYZ(Engine& engine, const Args& args) : DumpCustom(engine, xyz_args(args)) {}

  int modify_param(const Args& args, std::size_t k) override {
    const std::string& key = args[k];
    if (key == "time" || key == "units" || key == "label" || key == "element") {
      throw InputError(
          "dump_modify " + id + " " + key +
          ": not available for dump xyz (its frames are the count, the step line and type x y z)");
    }
    return DumpCustom::modify_param(args, k);
  }

 protected:
  void write_frame(std::FILE* fp, const std::vector<double>& rows, std::int64_t nrows, int stride) override {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%" PRId64 "\nAtoms. Timestep: %" PRId64 "\n", nrows,
                  static_cast<std::int64_t>(engine_.update->ntimestep));
    std::string out = buf;
    append_rows(fp, out, rows, nrows, stride);
  }
};

}  // namespace

GRANARY_DUMP_STYLE("xyz", DumpXYZ);

}  // namespace granary
