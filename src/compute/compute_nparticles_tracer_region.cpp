// compute ID group nparticles/tracer/region region_count REGION tracer FIXID
//     [periodic x|y|z IMAGE|all] [reset_marker yes|no]
// (LIGGGHTS 3.8): a global vector of 4: the number of the group's particles
// whose centre lies in REGION, how many of them are marked by the fix
// property/atom/tracer FIXID, and the mass of each. With reset_marker yes
// (the default) the marked particles counted are unmarked, so that a particle
// is counted once as it leaves through the region (residence-time
// distributions). With periodic, only particles in the given periodic image
// along that dimension are counted and unmarked (the last periodic keyword
// counts).
#include <mpi.h>

#include <string>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

int tracer_marker_field(Engine& e, const std::string& fix_id);

namespace {

class ComputeNParticlesTracerRegion : public Compute {
 public:
  ComputeNParticlesTracerRegion(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage =
        "compute ID group nparticles/tracer/region region_count REGION tracer FIXID [periodic x|y|z "
        "IMAGE|all] "
        "[reset_marker yes|no]";
    if (args.size() < 7 || args[3] != "region_count" || args[5] != "tracer")
      throw InputError("compute " + id + " nparticles/tracer/region: usage: " + usage);
    region_id_ = args[4];
    tracer_id_ = args[6];
    for (std::size_t k = 7; k < args.size();) {
      if (args[k] == "reset_marker" && k + 1 < args.size()) {
        reset_ = parse_bool(args[k + 1], "compute " + id + " reset_marker");
        k += 2;
      } else if (args[k] == "periodic" && k + 2 < args.size()) {
        const std::string& d = args[k + 1];
        if (d != "x" && d != "y" && d != "z")
          throw InputError("compute " + id + " periodic: dimension must be x, y or z, got '" + d + "'");
        dim_ = d[0] - 'x';
        image_all_ = args[k + 2] == "all";
        if (!image_all_)
          image_ = static_cast<int>(parse_int(args[k + 2], "compute " + id + " periodic image"));
        k += 3;
      } else {
        throw InputError("compute " + id + " nparticles/tracer/region: unknown or incomplete keyword '" +
                         args[k] + "'; usage: " + usage);
      }
    }
    size_vector = 4;
    extensive = true;
    init();
  }

  void init() override {
    engine_.domain->region_or_error(region_id_, "compute " + id);
    const Fix* f = engine_.modify->find_fix(tracer_id_);
    if (!f || f->style != "property/atom/tracer") {
      throw InputError("compute " + id + ": tracer " + tracer_id_ +
                       " is not the ID of a fix property/atom/tracer");
    }
  }

  void compute_vector() override {
    init();
    const Region* region = engine_.domain->region_or_error(region_id_, "compute " + id);
    Particles& p = *engine_.particles;
    const int field = tracer_marker_field(engine_, tracer_id_);
    double* marker = field >= 0 ? p.extras[field].data.data() : nullptr;
    double local[4] = {0.0, 0.0, 0.0, 0.0};
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || !region->match(p.x[i])) continue;
      if (dim_ >= 0 && !image_all_) {
        int im[3];
        Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
        if (im[dim_] != image_) continue;
      }
      local[0] += 1.0;
      local[2] += p.rmass[i];
      if (marker && marker[i] != 0.0) {
        local[1] += 1.0;
        local[3] += p.rmass[i];
        if (reset_) marker[i] = 0.0;
      }
    }
    vector.assign(4, 0.0);
    MPI_Allreduce(local, vector.data(), 4, MPI_DOUBLE, MPI_SUM, engine_.world);
  }

 private:
  std::string region_id_, tracer_id_;
  bool reset_ = true;
  int dim_ = -1;
  bool image_all_ = true;
  int image_ = 0;
};

}  // namespace

GRANARY_COMPUTE_STYLE("nparticles/tracer/region", ComputeNParticlesTracerRegion);

}  // namespace granary
