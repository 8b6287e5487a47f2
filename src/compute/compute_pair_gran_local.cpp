#include "compute/compute_pair_gran_local.h"

#include <algorithm>
#include <cmath>

#include "comm/comm.h"
#include "contact/contact_model.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "pair/pair_granular.h"
#include "particles/particles.h"

namespace granary {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

ComputePairGranLocal::ComputePairGranLocal(Engine& engine, const Args& args)
    : ComputeGranLocal(engine, args) {
  size_local_cols = local_cols(layout());
}

PairGranular& ComputePairGranLocal::pair() const {
  auto* pg = dynamic_cast<PairGranular*>(engine_.force->pair.get());
  if (!pg) {
    throw InputError("compute " + id + " " + style + " reports the contacts of a granular pair style, but " +
                     (engine_.force->pair ? "pair_style " + engine_.force->pair_style + " is not one"
                                          : std::string("no pair style is defined")) +
                     "; use e.g. pair_style gran model hertz tangential history");
  }
  return *pg;
}

int ComputePairGranLocal::history_size() const {
  const auto* pg = dynamic_cast<const PairGranular*>(engine_.force->pair.get());
  return pg ? pg->history_size() : 0;
}

void ComputePairGranLocal::init() {
  pair();
  size_local_cols = local_cols(layout());
}

void ComputePairGranLocal::compute_local() {
  PairGranular& pg = pair();
  Particles& p = *engine_.particles;
  const Neighbor& nb = *engine_.neighbor;
  const std::string where = "compute " + id + " (" + style + ")";
  const std::size_t nlist = nb.neigh.size();
  ContactHistory* hist = pg.history();
  const int nh = pg.history_size();
  if (nb.offset.size() != static_cast<std::size_t>(p.nlocal) + 1 || pg.materials().ntypes() < p.ntypes ||
      (hist && hist->entries() != nlist && nlist > 0))
    throw InputError(where +
                     " reports the contacts of the neighbour lists and contact history of a run: use it "
                     "during a run, or after `run 0` when particles were added or deleted or the pair style "
                     "changed since the last run");
  if (pg.spec().surface == contact::SurfaceModel::Multicontact)
    throw InputError(where +
                     " recomputes the contact forces from the positions, which 'surface "
                     "multicontact' would give without its radius changes (those come from the "
                     "previous step's contacts): not supported with fix multicontact/halfspace");
  const Layout L = layout();
  size_local_cols = local_cols(L);

  // ghosts get the current velocities and spins (after the last forward
  // communication they hold the half-step ones); positions do not change
  engine_.comm->forward_comm();
  // a ghost is a periodic image when its position differs from its owner's:
  // the owners' positions are forwarded without the periodic shift
  std::vector<double> unshifted;
  const Domain& dom = *engine_.domain;
  const bool periodic = dom.periodic[0] || dom.periodic[1] || dom.periodic[2];
  if (L.id >= 0 && periodic) {
    unshifted.assign(3 * static_cast<std::size_t>(p.size()), 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      for (int d = 0; d < 3; ++d)
        unshifted[3 * i + d] = p.x[i][d];
    engine_.comm->forward_comm_field(unshifted, 3);
  }

  // the torque is the whole torque of the contact on its first particle,
  // rolling friction included (as LIGGGHTS 3.8 writes it)
  const contact::ModelSpec& spec = pg.spec();
  const MaterialTable& materials = pg.materials();
  const double* body_mass = FieldRef(p, kBodyMassField).data(p);
  auto mass = [&](int a) { return body_mass && body_mass[a] > 0.0 ? body_mass[a] : p.rmass[a]; };

  array_local.clear();
  row_i.clear();
  row_j.clear();
  std::vector<double> h(std::max(nh, 1)), stored(std::max(nh, 1));
  std::vector<double> row(L.ncols);
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit)) continue;
    for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const int j = nb.neigh[k];
      if (!(p.mask[j] & groupbit)) continue;
      // with newton off a contact with a ghost is listed on both ranks: the
      // rank of the particle with the smaller id reports it
      if (j >= p.nlocal && p.id[i] > p.id[j]) continue;
      const Vec3 d = p.x[i] - p.x[j];
      const double rsum = p.radius[i] + p.radius[j];
      const double r2 = d.squaredNorm();
      if (!(r2 < rsum * rsum) || r2 == 0.0) continue;

      // the pair loop's geometry, operation for operation
      const double r = std::sqrt(r2);
      const double inv_r = 1.0 / r;
      contact::ContactState c;
      c.n = d * inv_r;
      c.overlap = rsum - r;
      c.r_i = p.radius[i];
      c.r_j = p.radius[j];
      c.r_eff = c.r_i * c.r_j / (c.r_i + c.r_j);
      const double m_i = mass(i), m_j = mass(j);
      c.m_eff = m_i * m_j / (m_i + m_j);
      c.i_roll = contact::rolling_inertia(m_i, c.r_i, m_j, c.r_j);
      c.v_rel = p.v[i] - p.v[j];
      c.omega_i = p.omega[i];
      c.omega_j = p.omega[j];
      c.dt = 0.0;  // the history as stored, not advanced
      const double* kept = hist ? hist->find(k) : nullptr;
      for (int q = 0; q < nh; ++q)
        stored[q] = kept ? kept[q] : 0.0;
      std::copy(stored.begin(), stored.end(), h.begin());
      contact::ContactResult res;
      contact::evaluate(spec, c, materials(p.type[i], p.type[j]), h.data(), res);

      auto put3 = [&row](int at, const Vec3& v) {
        for (int q = 0; q < 3; ++q)
          row[at + q] = v[q];
      };
      if (L.pos >= 0) {
        put3(L.pos, p.x[i]);
        put3(L.pos + 3, p.x[j]);
      }
      if (L.vel >= 0) {
        put3(L.vel, p.v[i]);
        put3(L.vel + 3, p.v[j]);
      }
      if (L.id >= 0) {
        row[L.id] = static_cast<double>(p.id[i]);
        row[L.id + 1] = static_cast<double>(p.id[j]);
        bool image = false;
        if (!unshifted.empty() && j >= p.nlocal)
          for (int q = 0; q < 3; ++q)
            image = image || unshifted[3 * static_cast<std::size_t>(j) + q] != p.x[j][q];
        row[L.id + 2] = image ? 1.0 : 0.0;
      }
      const Vec3 fn = res.force.dot(c.n) * c.n;
      if (L.force >= 0) put3(L.force, res.force);
      if (L.force_normal >= 0) put3(L.force_normal, fn);
      if (L.force_tangential >= 0) put3(L.force_tangential, res.force - fn);
      if (L.torque >= 0) put3(L.torque, res.torque_i);
      for (int q = 0; q < L.nhistory && L.history >= 0; ++q)
        row[L.history + q] = stored[q];
      if (L.contact_area >= 0) {
        // the circle where the two sphere surfaces intersect, at distance s
        // from the centre of i
        const double s = (r2 + c.r_i * c.r_i - c.r_j * c.r_j) / (2.0 * r);
        row[L.contact_area] = kPi * std::max(0.0, c.r_i * c.r_i - s * s);
      }
      if (L.delta >= 0) row[L.delta] = c.overlap;
      if (L.contact_point >= 0) put3(L.contact_point, p.x[i] - d * (c.r_i / rsum));
      array_local.insert(array_local.end(), row.begin(), row.end());
      row_i.push_back(i);
      row_j.push_back(j);
    }
  }
  size_local_rows = static_cast<int>(row_i.size());
}

GRANARY_COMPUTE_STYLE("pair/gran/local", ComputePairGranLocal);

}  // namespace granary
