// compute ID group multisphere [property NAME ...]: per-clump values of fix
// multisphere.
//
// Properties (default: xcm vcm omega quat): xcm (3, centre wrapped into a
// periodic box), vcm (3), omega (3), quat (4: w i j k), angmom (3), fcm (3),
// torque (3), inertia (3, principal moments), masstotal (1), density (1),
// atomtype (1), nspheres (1), id_multisphere (1). With C columns in all:
//   global vector: C values per clump in id order, c_ID[(b-1)*C + c] for clump
//                  b = 1..N and column c = 1..C (its length follows N; C zeros
//                  while there is no clump);
//   per-atom:      each sub-sphere carries its clump's C values (zeros for free
//                  spheres), c_ID[c] in dumps and atom-style variables.
// The group is ignored (every clump is listed). `rigid` is LIGGGHTS' other
// name of this style. ex_space, ey_space, ez_space (3 each): the principal
// axes in the space frame.
//
// compute ID group multisphere/single id BODY [property NAME ...]: the same
// values of the one clump with id BODY, as a global vector of C values
// (zeros while there is no such clump).
#include <Eigen/Geometry>
#include <algorithm>
#include <map>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "particles/clumps.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::map<std::string, int>& property_sizes() {
  static const std::map<std::string, int> sizes = {
      {"xcm", 3},      {"vcm", 3},      {"omega", 3},          {"quat", 4},      {"angmom", 3},
      {"fcm", 3},      {"torque", 3},   {"inertia", 3},        {"masstotal", 1}, {"density", 1},
      {"atomtype", 1}, {"nspheres", 1}, {"id_multisphere", 1}, {"ex_space", 3},  {"ey_space", 3},
      {"ez_space", 3}};
  return sizes;
}

class ComputeMultisphere : public Compute, public BodyOutput {
 public:
  ComputeMultisphere(Engine& engine, const Args& args, bool single = false)
      : Compute(engine, args), single_(single) {
    const std::string usage = single ? "compute ID group-ID multisphere/single id BODY [property NAME ...]"
                                     : "compute ID group-ID " + style + " [property NAME ...]";
    std::size_t first = 3;
    if (single) {
      if (args.size() < 5 || args[3] != "id") throw InputError("usage: " + usage);
      body_ = parse_int(args[4], "compute " + id + " multisphere/single id");
      if (body_ < 1) throw InputError("compute " + id + " multisphere/single: the clump id must be >= 1");
      first = 5;
    }
    if (args.size() > first) {
      if (args[first] != "property" || args.size() == first + 1) throw InputError("usage: " + usage);
      for (std::size_t k = first + 1; k < args.size(); ++k)
        props_.push_back(args[k] == "mass" ? "masstotal" : args[k]);
    } else {
      props_ = {"xcm", "vcm", "omega", "quat"};
    }
    ncols_ = 0;
    std::vector<std::string> known;
    for (const auto& kv : property_sizes())
      known.push_back(kv.first);
    for (const auto& name : props_) {
      auto it = property_sizes().find(name);
      if (it == property_sizes().end()) {
        const std::string hint = did_you_mean(name, known);
        throw InputError("compute " + id + " " + style + ": unknown property '" + name + "'" +
                         (name == "clumptype"
                              ? "; the template of a clump is not kept (use atomtype or nspheres)"
                              : (hint.empty() ? "" : "; " + hint)));
      }
      ncols_ += it->second;
    }
    if (single) {
      size_vector = ncols_;
      return;
    }
    peratom_flag = true;
    peratom_cols = ncols_ == 1 ? 0 : ncols_;
    if (engine.clumps) bodies_changed(engine.clumps->bodies().size());
  }

  // with no clump yet, one clump's worth of zeros (so thermo columns can be set up before insertion)
  void bodies_changed(int nbodies) override {
    if (!single_) size_vector = ncols_ * std::max(1, nbodies);
  }

  void init() override {
    Clumps* ms = fix();
    bodies_changed(ms->bodies().size());
  }

  void compute_vector() override {
    Clumps* ms = fix();
    ms->sync_bodies();
    if (single_) {
      vector.assign(ncols_, 0.0);
      const int b = ms->bodies().find(static_cast<tagint>(body_));
      if (b >= 0) values(*ms, b, vector.data());
      return;
    }
    const int n = ms->bodies().size();
    vector.assign(static_cast<std::size_t>(ncols_) * std::max(1, n), 0.0);
    for (int b = 0; b < n; ++b)
      values(*ms, b, &vector[static_cast<std::size_t>(b) * ncols_]);
  }

  void compute_peratom() override {
    // (the owned sub-spheres' bodies are current on this rank; the call keeps
    // all ranks' records alike for later outputs and costs nothing when current)
    Clumps* ms = fix();
    ms->sync_bodies();
    const Particles& p = *engine_.particles;
    std::vector<double> row(ncols_);
    if (ncols_ == 1)
      vector_atom.assign(p.nlocal, 0.0);
    else
      array_atom.assign(ncols_, std::vector<double>(p.nlocal, 0.0));
    for (int i = 0; i < p.nlocal; ++i) {
      const int b = p.body[i] >= 0 ? ms->bodies().find(p.body[i]) : -1;
      if (b < 0) continue;
      values(*ms, b, row.data());
      if (ncols_ == 1)
        vector_atom[i] = row[0];
      else
        for (int c = 0; c < ncols_; ++c)
          array_atom[c][i] = row[c];
    }
  }

 private:
  Clumps* fix() const {
    Clumps* ms = engine_.clumps;
    if (!ms) throw InputError("compute " + id + " " + style + " needs fix multisphere");
    return ms;
  }

  void values(const Clumps& ms, int b, double* out) const {
    const Bodies& B = ms.bodies();
    int c = 0;
    auto put3 = [&](const Vec3& v) {
      for (int d = 0; d < 3; ++d)
        out[c++] = v[d];
    };
    for (const auto& name : props_) {
      if (name == "xcm")
        put3(ms.wrapped_centre(b));
      else if (name == "vcm")
        put3(B.vcm[b]);
      else if (name == "omega")
        put3(B.omega[b]);
      else if (name == "angmom")
        put3(B.angmom[b]);
      else if (name == "fcm")
        put3(B.fcm[b]);
      else if (name == "torque")
        put3(B.torque[b]);
      else if (name == "inertia")
        put3(B.inertia[b]);
      else if (name == "quat") {
        out[c++] = B.quat[b].w();
        out[c++] = B.quat[b].x();
        out[c++] = B.quat[b].y();
        out[c++] = B.quat[b].z();
      } else if (name == "masstotal")
        out[c++] = B.mass[b];
      else if (name == "density")
        out[c++] = B.density[b];
      else if (name == "atomtype")
        out[c++] = B.type[b];
      else if (name == "nspheres")
        out[c++] = B.nspheres[b];
      else if (name == "id_multisphere")
        out[c++] = static_cast<double>(B.tag[b]);
      else  // ex_space, ey_space, ez_space: a column of the rotation body -> space
        put3(B.quat[b].toRotationMatrix().col(name[1] - 'x'));
    }
  }

  std::vector<std::string> props_;
  int ncols_ = 0;
  bool single_ = false;
  long long body_ = 0;  // multisphere/single: the clump's id
};

class ComputeMultisphereSingle : public ComputeMultisphere {
 public:
  ComputeMultisphereSingle(Engine& engine, const Args& args) : ComputeMultisphere(engine, args, true) {}
};

}  // namespace

GRANARY_COMPUTE_STYLE("multisphere", ComputeMultisphere);
GRANARY_COMPUTE_STYLE("rigid", ComputeMultisphere);
GRANARY_COMPUTE_STYLE("multisphere/single", ComputeMultisphereSingle);

}  // namespace granary
