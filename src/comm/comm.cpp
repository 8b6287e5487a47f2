#include "comm/comm.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "comm/balance.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "neighbor/contact_history.h"
#include "particles/particles.h"

namespace granary {

namespace {
int nb(int p) {
  return p < 0 ? MPI_PROC_NULL : p;
}

// Exchange counts then doubles with one partner each way.
void sendrecv_doubles(const std::vector<double>& send, int sendproc, std::vector<double>& recv, int recvproc,
                      MPI_Comm world) {
  int nsend = static_cast<int>(send.size()), nrecv = 0;
  MPI_Sendrecv(&nsend, 1, MPI_INT, sendproc, 1, &nrecv, 1, MPI_INT, recvproc, 1, world, MPI_STATUS_IGNORE);
  if (recvproc == MPI_PROC_NULL) nrecv = 0;
  recv.resize(nrecv);
  MPI_Sendrecv(send.data(), sendproc == MPI_PROC_NULL ? 0 : nsend, MPI_DOUBLE, sendproc, 2, recv.data(),
               nrecv, MPI_DOUBLE, recvproc, 2, world, MPI_STATUS_IGNORE);
}
}  // namespace

Comm::Comm(Engine& engine) : engine_(engine) {}

void Comm::processors_command(const Args& args) {
  require_args(args, 3, 3, "processors Px Py Pz  (each an integer or *)");
  if (engine_.domain->box_exist) throw InputError("processors must come before the box is created");
  for (int d = 0; d < 3; ++d) {
    user_grid[d] = args[d] == "*" ? 0 : static_cast<int>(parse_int(args[d], "processors"));
    if (user_grid[d] < 0) throw InputError("processor counts must be positive or *");
  }
  int known = 1;
  for (int d = 0; d < 3; ++d)
    known *= user_grid[d] > 0 ? user_grid[d] : 1;
  if (engine_.nprocs % known != 0) {
    throw InputError("processors " + join(args) + " does not divide the " + std::to_string(engine_.nprocs) +
                     " MPI ranks");
  }
}

void Comm::modify_command(const Args& args) {
  // comm_modify / communicate: [single] [vel yes|no] [cutoff D] [mode single]
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& w = args[k];
    if (w == "single" || w == "multi") continue;
    if (w == "mode" && k + 1 < args.size()) {
      ++k;
      continue;
    }
    if ((w == "vel") && k + 1 < args.size()) {
      ghost_velocity = parse_bool(args[++k], "vel");
      if (!ghost_velocity) {
        throw InputError(
            "comm_modify vel no: granular contacts need the velocities and spins of "
            "ghost particles; use vel yes (the default)");
      }
    } else if ((w == "cutoff") && k + 1 < args.size()) {
      cutghost_user = parse_double(args[++k], "cutoff");
    } else {
      throw InputError("unknown keyword '" + w + "' in comm_modify; expected vel yes|no or cutoff D");
    }
  }
}

void Comm::style_command(const Args& args) {
  require_args(args, 1, 1, "comm_style brick|tiled");
  Style want;
  if (args[0] == "brick")
    want = Style::kBrick;
  else if (args[0] == "tiled")
    want = Style::kTiled;
  else
    throw InputError("unknown comm_style '" + args[0] +
                     "'; expected brick (a processor grid) or tiled (any boxes, needed by balance rcb)");
  const bool had_tree = !rcb_.empty();
  style = want;
  if (want == Style::kBrick && had_tree) {
    // back to the grid's boxes: particles go to their owners there at once
    rcb_.clear();
    if (engine_.domain->box_exist) Balancer(engine_).migrate();
  }
}

void Comm::set_rcb(std::vector<RcbNode> tree) {
  const int n = engine_.nprocs;
  std::vector<std::array<double, 3>> lo(n), hi(n);
  std::vector<int> seen(n, 0);
  // walk the tree with the box of each node
  struct Item {
    int node;
    std::array<double, 3> lo, hi;
  };
  std::vector<Item> stack{{0, {{0.0, 0.0, 0.0}}, {{1.0, 1.0, 1.0}}}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const RcbNode& node = tree.at(static_cast<std::size_t>(it.node));
    if (node.rank >= 0) {
      if (node.rank >= n || seen[node.rank]++) throw std::logic_error("rcb tree: rank in more than one leaf");
      lo[node.rank] = it.lo;
      hi[node.rank] = it.hi;
      continue;
    }
    Item below = it, above = it;
    below.node = node.lo;
    below.hi[node.dim] = node.cut;
    above.node = node.hi;
    above.lo[node.dim] = node.cut;
    stack.push_back(above);
    stack.push_back(below);
  }
  for (int r = 0; r < n; ++r)
    if (!seen[r]) throw std::logic_error("rcb tree: a rank without a box");
  rcb_ = std::move(tree);
  rcb_lo_ = std::move(lo);
  rcb_hi_ = std::move(hi);
}

double Comm::frac_coord(int d, double f) const {
  const Domain& dom = *engine_.domain;
  if (f >= 1.0) return dom.boxhi[d];
  if (f <= 0.0) return dom.boxlo[d];
  return dom.boxlo[d] + f * dom.prd[d];
}

void Comm::rank_box(int r, Vec3& lo, Vec3& hi) const {
  if (tiled() && !rcb_.empty()) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = frac_coord(d, rcb_lo_[r][d]);
      hi[d] = frac_coord(d, rcb_hi_[r][d]);
    }
    return;
  }
  const int loc[3] = {r % procgrid[0], (r / procgrid[0]) % procgrid[1], r / (procgrid[0] * procgrid[1])};
  for (int d = 0; d < 3; ++d) {
    lo[d] = cut_coord(d, loc[d]);
    hi[d] = cut_coord(d, loc[d] + 1);
  }
}

// Factor nprocs into a grid that minimises the surface between subdomains.
void Comm::choose_grid() {
  const int n = engine_.nprocs;
  const Vec3& prd = engine_.domain->prd;
  double best = std::numeric_limits<double>::max();
  std::array<int, 3> grid{{1, 1, n}};
  for (int px = 1; px <= n; ++px) {
    if (n % px || (user_grid[0] && user_grid[0] != px)) continue;
    for (int py = 1; py <= n / px; ++py) {
      if ((n / px) % py || (user_grid[1] && user_grid[1] != py)) continue;
      const int pz = n / px / py;
      if (user_grid[2] && user_grid[2] != pz) continue;
      if (engine_.domain->dimension == 2 && pz != 1) continue;  // 2d: one rank along z
      const double ax = prd[0] / px, ay = prd[1] / py, az = prd[2] / pz;
      const double surf = ax * ay + ay * az + ax * az;
      if (surf < best - 1e-12 * surf) {
        best = surf;
        grid = {px, py, pz};
      }
    }
  }
  if (best == std::numeric_limits<double>::max()) {
    throw InputError("the processors grid does not match " + std::to_string(n) + " MPI ranks");
  }
  procgrid = grid;
  const int me = engine_.rank;
  myloc = {me % procgrid[0], (me / procgrid[0]) % procgrid[1], me / (procgrid[0] * procgrid[1])};
  for (int d = 0; d < 3; ++d) {
    for (int s = 0; s < 2; ++s) {
      std::array<int, 3> loc = myloc;
      loc[d] += s == 0 ? -1 : 1;
      if (loc[d] < 0 || loc[d] >= procgrid[d]) {
        if (!engine_.domain->periodic[d]) {
          procneigh[d][s] = -1;
          continue;
        }
        loc[d] = (loc[d] + procgrid[d]) % procgrid[d];
      }
      procneigh[d][s] = loc[0] + procgrid[0] * (loc[1] + procgrid[1] * loc[2]);
    }
    split[d].resize(procgrid[d] + 1);
    for (int k = 0; k <= procgrid[d]; ++k)
      split[d][k] = static_cast<double>(k) / procgrid[d];
  }
  grid_set_ = true;
}

void Comm::set_subdomain() {
  Domain& dom = *engine_.domain;
  if (tiled()) {
    rank_box(engine_.rank, dom.sublo, dom.subhi);
    return;
  }
  for (int d = 0; d < 3; ++d) {
    dom.sublo[d] = cut_coord(d, myloc[d]);
    dom.subhi[d] = cut_coord(d, myloc[d] + 1);
  }
}

double Comm::cut_coord(int d, int k, const std::vector<double>& cuts) const {
  const Domain& dom = *engine_.domain;
  if (k >= procgrid[d]) return dom.boxhi[d];
  if (k <= 0) return dom.boxlo[d];
  return dom.boxlo[d] + cuts[k] * dom.prd[d];
}

int Comm::slab_of(int d, double x, const std::vector<double>& cuts) const {
  // the same comparisons as exchange(): x < sublo goes down, x >= subhi goes up
  int lo = 0, hi = procgrid[d] - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (x >= cut_coord(d, mid, cuts))
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

void Comm::check_widths(const std::array<std::vector<double>, 3>& cuts, double width,
                        const std::string& advice) const {
  const Domain& dom = *engine_.domain;
  for (int d = 0; d < dom.dimension; ++d) {
    if (procgrid[d] == 1 && !dom.periodic[d]) continue;
    for (int k = 0; k < procgrid[d]; ++k) {
      const double w = cut_coord(d, k + 1, cuts[d]) - cut_coord(d, k, cuts[d]);
      if (width > w) {
        throw InputError("the ghost cutoff " + std::to_string(width) + " exceeds the width " +
                         std::to_string(w) + " of subdomain " + std::to_string(k + 1) + " of " +
                         std::to_string(procgrid[d]) + " along " + std::string(1, "xyz"[d]) + "; " + advice);
      }
    }
  }
}

void Comm::setup(double cutghost_needed) {
  if (!grid_set_) choose_grid();
  set_subdomain();
  cutghost = std::max(cutghost_needed, cutghost_user);
  if (tiled()) {
    // ghosts go straight to every box within the cutoff: only one periodic
    // image on each side is made
    const Domain& dom = *engine_.domain;
    for (int d = 0; d < dom.dimension; ++d) {
      if (dom.periodic[d] && cutghost > dom.prd[d]) {
        throw InputError("the ghost cutoff " + std::to_string(cutghost) + " exceeds the periodic length " +
                         std::to_string(dom.prd[d]) + " of the box along " + std::string(1, "xyz"[d]) +
                         "; use a smaller skin or a larger box");
      }
    }
    return;
  }
  // Ghosts come from the adjacent rank only, so every subdomain (not only
  // this rank's: the cuts may be uneven after balancing) must be at least
  // the ghost cutoff wide.
  check_widths(split, cutghost,
               "use fewer MPI ranks along that direction (processors command), a smaller skin or a "
               "larger box");
}

int Comm::owner_of(const Vec3& x) const {
  if (tiled() && !rcb_.empty()) {
    int node = 0;
    while (rcb_[node].rank < 0) {
      const RcbNode& n = rcb_[node];
      node = x[n.dim] >= frac_coord(n.dim, n.cut) ? n.hi : n.lo;
    }
    return rcb_[node].rank;
  }
  return rank_at(slab_of(0, x[0], split[0]), slab_of(1, x[1], split[1]), slab_of(2, x[2], split[2]));
}

void Comm::exchange(ContactHistory* history) {
  Particles& p = *engine_.particles;
  Domain& dom = *engine_.domain;
  p.clear_ghosts();
  for (int i = 0; i < p.nlocal; ++i)
    dom.remap(p.x[i], p.image[i]);

  // Particles outside a fixed ('f') boundary are lost; the caller acts on the count.
  nlost = 0;
  for (int i = 0; i < p.nlocal;) {
    bool out = false;
    for (int d = 0; d < 3; ++d) {
      out |= dom.boundary[d][0] == 'f' && p.x[i][d] < dom.boxlo[d];
      out |= dom.boundary[d][1] == 'f' && p.x[i][d] > dom.boxhi[d];
    }
    if (!out) {
      ++i;
      continue;
    }
    if (nlost == 0) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "particle %lld at (%g, %g, %g) with velocity (%g, %g, %g)",
                    static_cast<long long>(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2], p.v[i][0], p.v[i][1],
                    p.v[i][2]);
      first_lost = buf;
      lost_vmax = 0.0;
      lost_rmin = p.radius[i];
    }
    lost_vmax = std::max(lost_vmax, p.v[i].norm());
    lost_rmin = std::min(lost_rmin, p.radius[i]);
    ++nlost;
    engine_.delete_particle(i);  // slot i now holds another particle: look at it next
  }
  if (tiled()) {
    exchange_tiled(history);
    return;
  }

  for (int d = 0; d < 3; ++d) {
    if (procgrid[d] == 1) continue;
    // Repeat until nothing is outside along d (a particle may cross several subdomains).
    for (int pass = 0; pass < procgrid[d]; ++pass) {
      std::vector<double> send[2];
      int i = 0;
      while (i < p.nlocal) {
        int side = -1;
        if (p.x[i][d] < dom.sublo[d] && myloc[d] > 0)
          side = 0;
        else if (p.x[i][d] >= dom.subhi[d] && myloc[d] < procgrid[d] - 1)
          side = 1;
        else if (dom.periodic[d] && p.x[i][d] < dom.sublo[d])
          side = 0;
        else if (dom.periodic[d] && p.x[i][d] >= dom.subhi[d])
          side = 1;
        if (side < 0) {
          ++i;
          continue;
        }
        p.pack_exchange(i, send[side]);
        if (history) {
          const std::size_t at = send[side].size();
          history->pack_particle(p.id[i], send[side]);
          migrated_contacts += static_cast<long long>(send[side][at]);
        }
        ++migrated_particles;
        p.remove_local(i);
      }
      int moved_local = static_cast<int>(!send[0].empty() || !send[1].empty()), moved = 0;
      std::vector<double> recv;
      for (int s = 0; s < 2; ++s) {
        // send to the neighbour on side s, receive from the opposite one
        sendrecv_doubles(send[s], nb(procneigh[d][s]), recv, nb(procneigh[d][1 - s]), engine_.world);
        std::size_t m = 0;
        while (m < recv.size()) {
          m += p.unpack_exchange(&recv[m]);
          if (history) m += history->unpack_particle(p.id[p.nlocal - 1], &recv[m]);
        }
      }
      MPI_Allreduce(&moved_local, &moved, 1, MPI_INT, MPI_MAX, engine_.world);
      if (!moved) break;
    }
  }
}

void Comm::borders() {
  if (tiled()) {
    borders_tiled();
    return;
  }
  Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  p.clear_ghosts();
  swaps_.clear();
  std::vector<double> recv;
  // 2d: one layer of particles in z, no periodic images of it (LAMMPS' rule)
  const int ndims = dom.dimension == 2 ? 2 : 3;
  for (int d = 0; d < ndims; ++d) {
    const int nlast = p.size();  // both swaps of this dimension scan what existed before it
    for (int dir = 0; dir < 2; ++dir) {
      Swap s;
      s.dim = d;
      s.dir = dir;
      const bool at_edge = dir == 0 ? myloc[d] == 0 : myloc[d] == procgrid[d] - 1;
      s.active = procneigh[d][dir] >= 0 && (procgrid[d] > 1 || dom.periodic[d]);
      s.sendproc = s.active ? procneigh[d][dir] : MPI_PROC_NULL;
      // We receive from the opposite neighbour what it sends in this direction.
      const int opp = procneigh[d][1 - dir];
      s.recvproc = (opp >= 0 && (procgrid[d] > 1 || dom.periodic[d])) ? opp : MPI_PROC_NULL;
      s.shift.setZero();
      if (s.active && at_edge && dom.periodic[d]) s.shift[d] = dir == 0 ? dom.prd[d] : -dom.prd[d];
      sendbuf_.clear();
      if (s.active) {
        const double lo = dom.sublo[d] + cutghost, hi = dom.subhi[d] - cutghost;
        for (int i = 0; i < nlast; ++i) {
          const bool send = dir == 0 ? p.x[i][d] < lo : p.x[i][d] >= hi;
          if (send) {
            s.sendlist.push_back(i);
            p.pack_border(i, s.shift, sendbuf_);
          }
        }
      }
      sendrecv_doubles(sendbuf_, s.sendproc, recv, s.recvproc, engine_.world);
      s.firstrecv = p.size();
      std::size_t m = 0;
      while (m < recv.size())
        m += p.unpack_border(&recv[m]);
      s.nrecv = p.size() - s.firstrecv;
      swaps_.push_back(std::move(s));
    }
  }
}

// Message sizes are known from borders(): only the data travel each step, and
// swaps with no partner on either side are skipped.
void Comm::exchange_known(const std::vector<double>& send, int sendproc, std::vector<double>& recv,
                          std::size_t nrecv, int recvproc) {
  recv.resize(recvproc == MPI_PROC_NULL ? 0 : nrecv);
  MPI_Sendrecv(send.data(), sendproc == MPI_PROC_NULL ? 0 : static_cast<int>(send.size()), MPI_DOUBLE,
               sendproc, 3, recv.data(), static_cast<int>(recv.size()), MPI_DOUBLE, recvproc, 3,
               engine_.world, MPI_STATUS_IGNORE);
}

void Comm::forward_comm() {
  Particles& p = *engine_.particles;
  const int per = ghost_velocity ? 9 : 3;
  Vec3* const x = p.x.data();
  Vec3* const v = p.v.data();
  Vec3* const w = p.omega.data();
  if (tiled()) {
    const bool vel = ghost_velocity;
    tiled_forward(
        per,
        [=](int i, const Vec3& shift, double* out) {
          for (int d = 0; d < 3; ++d)
            out[d] = x[i][d] + shift[d];
          if (vel) {
            for (int d = 0; d < 3; ++d) {
              out[3 + d] = v[i][d];
              out[6 + d] = w[i][d];
            }
          }
        },
        [=](int j, const double* in) {
          x[j] = Vec3(in[0], in[1], in[2]);
          if (vel) {
            v[j] = Vec3(in[3], in[4], in[5]);
            w[j] = Vec3(in[6], in[7], in[8]);
          }
        });
    return;
  }
  for (const Swap& s : swaps_) {
    if (s.sendproc == MPI_PROC_NULL && s.recvproc == MPI_PROC_NULL) continue;
    sendbuf_.resize(s.sendlist.size() * per);
    double* out = sendbuf_.data();
    const Vec3 shift = s.shift;
    for (int i : s.sendlist) {
      for (int d = 0; d < 3; ++d)
        *out++ = x[i][d] + shift[d];
      if (ghost_velocity) {
        for (int d = 0; d < 3; ++d)
          *out++ = v[i][d];
        for (int d = 0; d < 3; ++d)
          *out++ = w[i][d];
      }
    }
    exchange_known(sendbuf_, s.sendproc, recvbuf_, static_cast<std::size_t>(s.nrecv) * per, s.recvproc);
    const int n = std::min<int>(s.nrecv, static_cast<int>(recvbuf_.size() / per));
    const double* in = recvbuf_.data();
    for (int k = 0; k < n; ++k) {
      const int j = s.firstrecv + k;
      x[j] = Vec3(in[0], in[1], in[2]);
      in += 3;
      if (ghost_velocity) {
        v[j] = Vec3(in[0], in[1], in[2]);
        w[j] = Vec3(in[3], in[4], in[5]);
        in += 6;
      }
    }
  }
}

void Comm::reverse_comm() {
  Particles& p = *engine_.particles;
  if (tiled()) {
    Vec3* const f = p.f.data();
    Vec3* const t = p.torque.data();
    tiled_reverse(
        6,
        [=](int j, double* out) {
          for (int d = 0; d < 3; ++d) {
            out[d] = f[j][d];
            out[3 + d] = t[j][d];
          }
        },
        [=](int i, const double* in) {
          for (int d = 0; d < 3; ++d) {
            f[i][d] += in[d];
            t[i][d] += in[3 + d];
          }
        });
    return;
  }
  for (auto it = swaps_.rbegin(); it != swaps_.rend(); ++it) {
    const Swap& s = *it;
    if (s.sendproc == MPI_PROC_NULL && s.recvproc == MPI_PROC_NULL) continue;
    sendbuf_.clear();
    if (s.recvproc != MPI_PROC_NULL) {
      for (int k = 0; k < s.nrecv; ++k) {
        const int j = s.firstrecv + k;
        for (int d = 0; d < 3; ++d)
          sendbuf_.push_back(p.f[j][d]);
        for (int d = 0; d < 3; ++d)
          sendbuf_.push_back(p.torque[j][d]);
      }
    }
    // back along the swap: to whom we received from, from whom we sent to
    exchange_known(sendbuf_, s.recvproc, recvbuf_, s.sendlist.size() * 6, s.sendproc);
    std::size_t m = 0;
    for (int i : s.sendlist) {
      if (m >= recvbuf_.size()) break;
      for (int d = 0; d < 3; ++d)
        p.f[i][d] += recvbuf_[m++];
      for (int d = 0; d < 3; ++d)
        p.torque[i][d] += recvbuf_[m++];
    }
  }
}

void Comm::forward_comm_field(std::vector<double>& data, int ncomp) {
  if (tiled()) {
    double* const a = data.data();
    const std::size_t n = static_cast<std::size_t>(ncomp);
    tiled_forward(
        ncomp, [=](int i, const Vec3&, double* out) { std::copy(a + i * n, a + (i + 1) * n, out); },
        [=](int j, const double* in) { std::copy(in, in + n, a + j * n); });
    return;
  }
  for (const Swap& s : swaps_) {
    sendbuf_.clear();
    for (int i : s.sendlist)
      sendbuf_.insert(sendbuf_.end(), data.begin() + static_cast<std::size_t>(i) * ncomp,
                      data.begin() + static_cast<std::size_t>(i + 1) * ncomp);
    sendrecv_doubles(sendbuf_, s.sendproc, recvbuf_, s.recvproc, engine_.world);
    std::copy(recvbuf_.begin(), recvbuf_.end(), data.begin() + static_cast<std::size_t>(s.firstrecv) * ncomp);
  }
}

void Comm::reverse_comm_field(std::vector<double>& data, int ncomp) {
  if (tiled()) {
    double* const a = data.data();
    const std::size_t n = static_cast<std::size_t>(ncomp);
    tiled_reverse(
        ncomp, [=](int j, double* out) { std::copy(a + j * n, a + (j + 1) * n, out); },
        [=](int i, const double* in) {
          for (std::size_t c = 0; c < n; ++c)
            a[i * n + c] += in[c];
        });
    return;
  }
  for (auto it = swaps_.rbegin(); it != swaps_.rend(); ++it) {
    const Swap& s = *it;
    sendbuf_.assign(data.begin() + static_cast<std::size_t>(s.firstrecv) * ncomp,
                    data.begin() + static_cast<std::size_t>(s.firstrecv + s.nrecv) * ncomp);
    sendrecv_doubles(sendbuf_, s.recvproc, recvbuf_, s.sendproc, engine_.world);
    std::size_t m = 0;
    for (int i : s.sendlist)
      for (int c = 0; c < ncomp; ++c)
        data[static_cast<std::size_t>(i) * ncomp + c] += recvbuf_[m++];
  }
}

// ---- comm_style tiled -------------------------------------------------------

void Comm::alltoall_buffers(std::vector<std::vector<double>>& send, std::vector<std::vector<double>>& recv,
                            const std::vector<std::size_t>* known_counts, int tag) {
  const int n = engine_.nprocs, me = engine_.rank;
  recv.resize(static_cast<std::size_t>(n));
  std::vector<long long> scount(n, 0), rcount(n, 0);
  for (int r = 0; r < n; ++r)
    scount[r] = r == me ? 0 : static_cast<long long>(send[r].size());
  if (known_counts) {
    for (int r = 0; r < n; ++r)
      rcount[r] = r == me ? 0 : static_cast<long long>((*known_counts)[r]);
  } else {
    MPI_Alltoall(scount.data(), 1, MPI_LONG_LONG, rcount.data(), 1, MPI_LONG_LONG, engine_.world);
  }
  std::vector<MPI_Request> reqs;
  reqs.reserve(2 * static_cast<std::size_t>(n));
  for (int r = 0; r < n; ++r) {
    if (r == me) continue;
    recv[r].resize(static_cast<std::size_t>(rcount[r]));
    if (rcount[r] == 0) continue;
    reqs.emplace_back();
    MPI_Irecv(recv[r].data(), static_cast<int>(rcount[r]), MPI_DOUBLE, r, tag, engine_.world, &reqs.back());
  }
  for (int r = 0; r < n; ++r) {
    if (r == me || scount[r] == 0) continue;
    reqs.emplace_back();
    MPI_Isend(send[r].data(), static_cast<int>(scount[r]), MPI_DOUBLE, r, tag, engine_.world, &reqs.back());
  }
  recv[me].swap(send[me]);  // this rank's own periodic images
  MPI_Waitall(static_cast<int>(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  for (auto& b : send)
    b.clear();  // sent: empty for the next exchange (capacity kept)
}

void Comm::exchange_tiled(ContactHistory* history) {
  Particles& p = *engine_.particles;
  const int n = engine_.nprocs, me = engine_.rank;
  if (n == 1) return;
  std::vector<std::vector<double>> send(static_cast<std::size_t>(n)), recv;
  int i = 0;
  while (i < p.nlocal) {
    const int owner = owner_of(p.x[i]);
    if (owner == me) {
      ++i;
      continue;
    }
    std::vector<double>& buf = send[owner];
    p.pack_exchange(i, buf);
    if (history) {
      const std::size_t at = buf.size();
      history->pack_particle(p.id[i], buf);
      migrated_contacts += static_cast<long long>(buf[at]);
    }
    ++migrated_particles;
    p.remove_local(i);
  }
  alltoall_buffers(send, recv, nullptr, 21);
  for (int r = 0; r < n; ++r) {
    std::size_t m = 0;
    while (m < recv[r].size()) {
      m += p.unpack_exchange(&recv[r][m]);
      if (history) m += history->unpack_particle(p.id[p.nlocal - 1], &recv[r][m]);
    }
  }
}

// Every owned particle within the ghost cutoff of another box (or of a
// periodic image of any box, this rank's own included) goes there as a
// ghost, in one message per rank. Boxes at a non-periodic face of the
// simulation box reach to infinity there (particles beyond a face belong to
// the rank at it), as the grid's swaps do.
void Comm::borders_tiled() {
  Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  const int n = engine_.nprocs, me = engine_.rank;
  p.clear_ghosts();
  tsend_.clear();
  trecv_.clear();
  const double inf = std::numeric_limits<double>::infinity();
  auto extended = [&](int r, Vec3& lo, Vec3& hi) {
    rank_box(r, lo, hi);
    for (int d = 0; d < 3; ++d) {
      if (dom.periodic[d]) continue;
      if (lo[d] <= dom.boxlo[d]) lo[d] = -inf;
      if (hi[d] >= dom.boxhi[d]) hi[d] = inf;
    }
  };
  Vec3 mylo, myhi;
  extended(me, mylo, myhi);
  // (rank, periodic image) pairs whose reach overlaps this box; a particle x
  // goes to one when lo <= x < hi (its reach in this rank's frame)
  struct Target {
    int proc;
    Vec3 shift, lo, hi;
  };
  std::vector<Target> targets;
  for (int r = 0; r < n; ++r) {
    Vec3 rlo, rhi;
    extended(r, rlo, rhi);
    int range[3][2];
    for (int d = 0; d < 3; ++d) {
      const bool images = dom.periodic[d] && !(d == 2 && dom.dimension == 2);
      range[d][0] = images ? -1 : 0;
      range[d][1] = images ? 1 : 0;
    }
    for (int sx = range[0][0]; sx <= range[0][1]; ++sx)
      for (int sy = range[1][0]; sy <= range[1][1]; ++sy)
        for (int sz = range[2][0]; sz <= range[2][1]; ++sz) {
          if (r == me && sx == 0 && sy == 0 && sz == 0) continue;
          Target t;
          t.proc = r;
          t.shift = Vec3(sx * dom.prd[0], sy * dom.prd[1], sz * dom.prd[2]);
          bool overlap = true;
          for (int d = 0; d < 3; ++d) {
            t.lo[d] = rlo[d] - cutghost - t.shift[d];
            t.hi[d] = rhi[d] + cutghost - t.shift[d];
            overlap = overlap && t.lo[d] < myhi[d] && t.hi[d] > mylo[d];
          }
          if (overlap) targets.push_back(t);
        }
  }
  const int nown = p.nlocal;
  // particles deeper inside this box than the cutoff are nobody's ghosts
  std::vector<int> edge;
  edge.reserve(static_cast<std::size_t>(nown) / 4);
  for (int i = 0; i < nown; ++i) {
    bool inner = true;
    for (int d = 0; d < 3; ++d)
      inner = inner && p.x[i][d] >= dom.sublo[d] + cutghost && p.x[i][d] < dom.subhi[d] - cutghost;
    if (!inner) edge.push_back(i);
  }
  std::vector<std::vector<double>>& send = tbuf_send_;
  send.resize(static_cast<std::size_t>(n));
  for (auto& b : send)
    b.clear();
  for (const Target& t : targets) {
    if (tsend_.empty() || tsend_.back().proc != t.proc) {
      tsend_.emplace_back();
      tsend_.back().proc = t.proc;
    }
    SendPeer& peer = tsend_.back();
    Segment seg;
    seg.shift = t.shift;
    seg.begin = static_cast<int>(peer.list.size());
    for (int i : edge) {
      const Vec3& x = p.x[i];
      if (x[0] >= t.lo[0] && x[0] < t.hi[0] && x[1] >= t.lo[1] && x[1] < t.hi[1] && x[2] >= t.lo[2] &&
          x[2] < t.hi[2]) {
        peer.list.push_back(i);
        p.pack_border(i, t.shift, send[t.proc]);
      }
    }
    seg.end = static_cast<int>(peer.list.size());
    if (seg.end > seg.begin) peer.segs.push_back(seg);
  }
  tsend_.erase(std::remove_if(tsend_.begin(), tsend_.end(), [](const SendPeer& s) { return s.list.empty(); }),
               tsend_.end());
  std::vector<std::vector<double>>& recv = tbuf_recv_;
  alltoall_buffers(send, recv, nullptr, 22);
  for (int r = 0; r < n; ++r) {
    if (recv[r].empty()) continue;
    RecvPeer rp;
    rp.proc = r;
    rp.first = p.size();
    std::size_t m = 0;
    while (m < recv[r].size())
      m += p.unpack_border(&recv[r][m]);
    rp.count = p.size() - rp.first;
    trecv_.push_back(rp);
  }
}

template <class Pack, class Unpack>
void Comm::tiled_forward(int per, Pack pack, Unpack unpack) {
  const int n = engine_.nprocs;
  std::vector<std::vector<double>>& send = tbuf_send_;
  send.resize(static_cast<std::size_t>(n));
  for (const SendPeer& peer : tsend_) {
    std::vector<double>& b = send[peer.proc];
    b.resize(peer.list.size() * static_cast<std::size_t>(per));
    double* out = b.data();
    for (const Segment& seg : peer.segs) {
      for (int k = seg.begin; k < seg.end; ++k, out += per)
        pack(peer.list[k], seg.shift, out);
    }
  }
  std::vector<std::size_t> counts(static_cast<std::size_t>(n), 0);
  for (const RecvPeer& rp : trecv_)
    counts[rp.proc] = static_cast<std::size_t>(rp.count) * per;
  alltoall_buffers(send, tbuf_recv_, &counts, 23);
  for (const RecvPeer& rp : trecv_) {
    const double* in = tbuf_recv_[rp.proc].data();
    for (int k = 0; k < rp.count; ++k, in += per)
      unpack(rp.first + k, in);
  }
}

template <class Pack, class Unpack>
void Comm::tiled_reverse(int per, Pack pack, Unpack unpack) {
  const int n = engine_.nprocs;
  std::vector<std::vector<double>>& send = tbuf_send_;
  send.resize(static_cast<std::size_t>(n));
  for (const RecvPeer& rp : trecv_) {
    std::vector<double>& b = send[rp.proc];
    b.resize(static_cast<std::size_t>(rp.count) * per);
    double* out = b.data();
    for (int k = 0; k < rp.count; ++k, out += per)
      pack(rp.first + k, out);
  }
  std::vector<std::size_t> counts(static_cast<std::size_t>(n), 0);
  for (const SendPeer& peer : tsend_)
    counts[peer.proc] = peer.list.size() * static_cast<std::size_t>(per);
  alltoall_buffers(send, tbuf_recv_, &counts, 24);
  for (const SendPeer& peer : tsend_) {
    const double* in = tbuf_recv_[peer.proc].data();
    for (int i : peer.list) {
      unpack(i, in);
      in += per;
    }
  }
}

// `processors`, `communicate` and `comm_modify` commands.
void cmd_processors(Engine& e, const Args& a) {
  e.comm->processors_command(a);
}
void cmd_comm_modify(Engine& e, const Args& a) {
  e.comm->modify_command(a);
}
GRANARY_COMMAND("processors", cmd_processors);
GRANARY_COMMAND("communicate", cmd_comm_modify);
GRANARY_COMMAND("comm_modify", cmd_comm_modify);
void cmd_comm_style(Engine& e, const Args& a) {
  e.comm->style_command(a);
}
GRANARY_COMMAND("comm_style", cmd_comm_style);

}  // namespace granary
