// fix ID group heat/gran initial_temperature T0 [contact_area overlap|projection|constant A]
//                         [area_correction yes|no] [store_contact_data no]
// (also heat/gran/conduction; LIGGGHTS' model of Chaudhuri et al. 2006):
// heat conduction between particles in contact, with a uniform temperature
// inside each particle. Through a contact of area A between particles i and
// j the heat flow into i is
//   Q_ij = h_ij (T_j - T_i),   h_ij = 4 k_i k_j / (k_i + k_j) sqrt(A),
// and every particle of the group follows
//   m_i c_i dT_i/dt = sum_j Q_ij + heatSource_i
// by explicit Euler steps: the flows of a step come from the temperatures at
// its start, the temperature update is the last thing of the step. Particles
// outside the group exchange heat with the group but keep their temperature.
// k (thermalConductivity) and c (thermalCapacity) are per-type properties of
// fix property/global. The fix owns three per-particle properties, each a fix
// property/atom with the same ID (LIGGGHTS' names): Temp (starts at T0, in
// restart files, sent to ghosts every step), heatSource (in restart files, set
// with `set ... property/atom heatSource W`), heatFlux (the sum of the Q_ij of
// the step). f_ID is the thermal energy sum m c T of all particles (as
// LIGGGHTS 3.8 computes it, although its manual says the group).
// contact_area: overlap (default) = pi a^2 of the circle where the two sphere
// surfaces intersect; projection = pi r_max^2 (LIGGGHTS 3.8 takes the larger
// radius; its manual says the smaller); constant A.
// area_correction yes: the overlap is scaled by (Y*/Y*_orig)^e before the
// area is computed (what LIGGGHTS 3.8 does; to first order the area scales
// by the same factor, as its manual says), Y* of youngsModulus and
// poissonsRatio, Y*_orig of youngsModulusOriginal (per type), e = 2/3 for a
// Hertz and 1 for a Hooke normal model.
#include <mpi.h>

#include <cmath>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/global_property.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "pair/pair_granular.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr double kPi = 3.14159265358979323846;

class FixHeatGran : public Fix {
 public:
  FixHeatGran(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group " + args[2] +
                              " initial_temperature T0 [contact_area overlap|projection|constant A] "
                              "[area_correction yes|no] [store_contact_data no]";
    require_args(args, 5, 11, usage);
    if (args[3] != "initial_temperature")
      throw InputError("fix " + id + " " + style +
                       ": the first keyword must be initial_temperature; usage: " + usage);
    t0_ = parse_double(args[4], "fix " + id + " initial_temperature");
    for (std::size_t k = 5; k < args.size(); k += 2) {
      const std::string& key = args[k];
      if (k + 1 >= args.size()) throw InputError("fix " + id + " " + style + ": " + key + " needs a value");
      const std::string& val = args[k + 1];
      if (key == "contact_area") {
        if (val == "overlap") {
          area_ = Area::Overlap;
        } else if (val == "projection") {
          area_ = Area::Projection;
        } else if (val == "constant") {
          if (k + 2 >= args.size())
            throw InputError("fix " + id + " " + style + ": contact_area constant needs the area");
          area_ = Area::Constant;
          area_value_ = parse_double(args[k + 2], "fix " + id + " contact_area constant");
          if (!(area_value_ > 0.0))
            throw InputError("fix " + id + " " + style + ": contact_area constant must be positive");
          ++k;
        } else {
          throw InputError("fix " + id + " " + style +
                           ": contact_area must be overlap, projection or constant, got '" + val + "'");
        }
      } else if (key == "area_correction") {
        if (val != "yes" && val != "no")
          throw InputError("fix " + id + " " + style + ": area_correction must be yes or no, got '" + val +
                           "'");
        area_correction_ = val == "yes";
      } else if (key == "store_contact_data") {
        if (val == "yes")
          throw InputError(
              "fix " + id + " " + style +
              ": store_contact_data yes (per-particle contact counts, areas and wall heat flux) is "
              "not supported; leave it out or give no");
        if (val != "no")
          throw InputError("fix " + id + " " + style + ": store_contact_data must be yes or no, got '" + val +
                           "'");
      } else {
        throw InputError("fix " + id + " " + style + ": unknown keyword '" + key +
                         "' (contact_area, area_correction, store_contact_data); usage: " + usage);
      }
    }
    // the per-particle properties, as fix property/atom with LIGGGHTS' IDs;
    // one defined already (by the script, or an earlier heat fix) is kept
    char t0[64];
    std::snprintf(t0, sizeof t0, "%.17g", t0_);
    define_property({"Temp", "all", "property/atom", "Temp", "scalar", "yes", "yes", "no", t0});
    define_property({"heatSource", "all", "property/atom", "heatSource", "scalar", "yes", "no", "no", "0"});
    define_property({"heatFlux", "all", "property/atom", "heatFlux", "scalar", "no", "no", "yes", "0"});
    scalar_flag = true;
  }

  unsigned hooks() const override { return POST_FORCE | FINAL_INTEGRATE; }

  void init() override {
    const Particles& p = *engine_.particles;
    temp_index_ = p.find_field("Temp");
    source_index_ = p.find_field("heatSource");
    flux_index_ = p.find_field("heatFlux");
    if (temp_index_ < 0 || source_index_ < 0 || flux_index_ < 0)
      throw InputError(
          "fix " + id + " " + style +
          ": its per-particle properties Temp, heatSource and heatFlux were removed (unfix); define "
          "the fix again");
    const Modify& m = *engine_.modify;
    const std::string by = "fix " + id + " " + style;
    const GlobalProperty& k = m.require_property("thermalConductivity", by);
    const GlobalProperty& c = m.require_property("thermalCapacity", by);
    const int nt = p.ntypes;
    std::vector<double> conductivity(nt + 1, 0.0);
    capacity_.assign(nt + 1, 0.0);
    for (int t = 1; t <= nt; ++t) {
      conductivity[t] = k.per_type(t);
      capacity_[t] = c.per_type(t);
      if (!(conductivity[t] > 0.0) || !(capacity_[t] > 0.0))
        throw InputError(by +
                         ": thermalConductivity and thermalCapacity must be positive for every type (type " +
                         std::to_string(t) + ")");
    }
    // per type pair: 4 k_i k_j / (k_i + k_j), and the overlap factor of area_correction
    conductance_.assign(static_cast<std::size_t>(nt + 1) * (nt + 1), 0.0);
    for (int a = 1; a <= nt; ++a)
      for (int b = 1; b <= nt; ++b)
        conductance_[static_cast<std::size_t>(a) * (nt + 1) + b] =
            4.0 * conductivity[a] * conductivity[b] / (conductivity[a] + conductivity[b]);
    correction_.assign(static_cast<std::size_t>(nt + 1) * (nt + 1), 1.0);
    if (area_correction_) {
      if (area_ != Area::Overlap)
        throw InputError(by + ": area_correction yes applies to contact_area overlap only");
      const auto* pair = dynamic_cast<const PairGranular*>(engine_.force->pair.get());
      if (!pair)
        throw InputError(
            by + ": area_correction yes needs a granular pair style (pair_style gran model hertz|hooke)");
      const contact::NormalModel nm = pair->spec().normal;
      const double e = nm == contact::NormalModel::Hooke || nm == contact::NormalModel::HookeStiffness ||
                               nm == contact::NormalModel::HookeHysteresis
                           ? 1.0
                           : 2.0 / 3.0;
      const GlobalProperty& y = m.require_property("youngsModulus", by);
      const GlobalProperty& nu = m.require_property("poissonsRatio", by);
      const GlobalProperty& yo = m.require_property("youngsModulusOriginal", by);
      for (int a = 1; a <= nt; ++a)
        for (int b = 1; b <= nt; ++b) {
          const double sa = 1.0 - nu.per_type(a) * nu.per_type(a), sb = 1.0 - nu.per_type(b) * nu.per_type(b);
          const double ystar = 1.0 / (sa / y.per_type(a) + sb / y.per_type(b));
          const double ystar_orig = 1.0 / (sa / yo.per_type(a) + sb / yo.per_type(b));
          correction_[static_cast<std::size_t>(a) * (nt + 1) + b] = std::pow(ystar / ystar_orig, e);
        }
    }
  }

  void setup() override { post_force(); }

  /// Heat flows of this step from the temperatures at its start.
  void post_force() override {
    Particles& p = *engine_.particles;
    const Neighbor& nb = *engine_.neighbor;
    // (a rank without particles has empty fields, and still takes part in
    // the communication)
    engine_.comm->forward_comm_field(p.extras[temp_index_].data, 1);
    const double* temp = p.extras[temp_index_].data.data();
    std::vector<double>& flux_field = p.extras[flux_index_].data;
    std::fill(flux_field.begin(), flux_field.end(), 0.0);
    double* flux = flux_field.data();
    const bool newton = engine_.force->newton_pair;
    const int nt1 = p.ntypes + 1;
    if (nb.offset.size() == static_cast<std::size_t>(p.nlocal) + 1) {
      for (int i = 0; i < p.nlocal; ++i) {
        for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          const int j = nb.neigh[k];
          if (p.body[i] >= 0 && p.body[i] == p.body[j]) continue;
          const double ri = p.radius[i], rj = p.radius[j], rsum = ri + rj;
          const double r2 = (p.x[i] - p.x[j]).squaredNorm();
          if (r2 >= rsum * rsum) continue;
          double area;
          if (area_ == Area::Overlap) {
            // the circle where the two sphere surfaces intersect, at distance
            // s from the centre of i; with area_correction, of spheres whose
            // overlap is scaled by the type pair's factor
            double r = std::sqrt(r2);
            if (area_correction_)
              r = rsum - (rsum - r) * correction_[static_cast<std::size_t>(p.type[i]) * nt1 + p.type[j]];
            const double s = (r * r + ri * ri - rj * rj) / (2.0 * r);
            area = kPi * std::max(0.0, ri * ri - s * s);
          } else if (area_ == Area::Projection) {
            // LIGGGHTS 3.8 takes the larger radius (its manual says the smaller)
            const double rmax = std::max(ri, rj);
            area = kPi * rmax * rmax;
          } else {
            area = area_value_;
          }
          const double h =
              conductance_[static_cast<std::size_t>(p.type[i]) * nt1 + p.type[j]] * std::sqrt(area);
          const double q = h * (temp[j] - temp[i]);  // into i
          flux[i] += q;
          if (j < p.nlocal || newton) flux[j] -= q;
        }
      }
    }
    if (newton) engine_.comm->reverse_comm_field(p.extras[flux_index_].data, 1);
  }

  void final_integrate() override {
    Particles& p = *engine_.particles;
    double* temp = p.extras[temp_index_].data.data();
    const double* flux = p.extras[flux_index_].data.data();
    const double* source = p.extras[source_index_].data.data();
    const double dt = engine_.update->dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      temp[i] += dt * (flux[i] + source[i]) / (p.rmass[i] * capacity_[p.type[i]]);
    }
  }

  /// Thermal energy sum m c T [J] of every particle: LIGGGHTS 3.8 sums over
  /// all particles, also those outside the group (its manual says the group).
  double compute_scalar() override {
    const Particles& p = *engine_.particles;
    double local = 0.0, all = 0.0;
    if (temp_index_ >= 0 && !capacity_.empty())
      for (int i = 0; i < p.nlocal; ++i)
        local += p.rmass[i] * capacity_[p.type[i]] * p.extras[temp_index_].data[i];
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

 private:
  enum class Area { Overlap, Projection, Constant };

  void define_property(const Args& a) {
    if (Fix* f = engine_.modify->find_fix(a[0])) {
      if (f->style != "property/atom")
        throw InputError("fix " + id + " " + style + " defines a per-particle property with fix ID " + a[0] +
                         ", which is already a " + f->style + " fix; use another ID for that fix");
      const Particles& p = *engine_.particles;
      const int k = p.find_field(a[3]);
      if (k < 0 || p.extras[k].ncomp != 1)
        throw InputError("fix " + id + " " + style + ": fix " + a[0] + " must be a scalar property/atom " +
                         a[3]);
      return;
    }
    engine_.modify->add_fix(a);
  }

  double t0_ = 0.0;
  Area area_ = Area::Overlap;
  double area_value_ = 0.0;
  bool area_correction_ = false;
  int temp_index_ = -1, source_index_ = -1, flux_index_ = -1;  // fields, found at init
  std::vector<double> capacity_, conductance_, correction_;
};

}  // namespace

GRANARY_FIX_STYLE("heat/gran", FixHeatGran);
GRANARY_FIX_STYLE("heat/gran/conduction", FixHeatGran);

}  // namespace granary
