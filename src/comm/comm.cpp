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
      s.nrecv = p.unpack_borders(recv.data(), recv.size());
      swaps_.push_back(std::move(s));
    }
  }
}

namespace {
// Room for n doubles: the buffer only ever grows, so that a step does not
// clear what a smaller message of another swap left shorter (std::vector
// zero-fills whatever it regains)
double* room(std::vector<double>& buf, std::size_t n) {
  if (buf.size() < n) buf.resize(n);
  return buf.data();
}
}  // namespace

// Both swaps of a dimension at once. Their send lists reach only particles
// that existed before the dimension's ghosts arrived (borders() scans those),
// so neither swap needs the other's data: each pair of swaps costs one wait
// instead of two. Message sizes are known from borders(): a swap receives
// exactly what its partner's send list holds, so both sides skip an empty
// message alike; each direction has its own tag (with two ranks along a
// periodic dimension both messages go to the same rank).
template <class Pack, class Unpack>
void Comm::brick_forward(int per, Pack pack, Unpack unpack) {
  for (std::size_t k = 0; k + 1 < swaps_.size(); k += 2) {
    MPI_Request req[4];
    int nreq = 0;
    std::size_t nin[2];
    for (int h = 0; h < 2; ++h) {
      const Swap& s = swaps_[k + h];
      nin[h] = s.recvproc == MPI_PROC_NULL ? 0 : static_cast<std::size_t>(s.nrecv) * per;
      if (nin[h] > 0)
        MPI_Irecv(room(pair_recv_[h], nin[h]), static_cast<int>(nin[h]), MPI_DOUBLE, s.recvproc, 30 + h,
                  engine_.world, &req[nreq++]);
    }
    for (int h = 0; h < 2; ++h) {
      const Swap& s = swaps_[k + h];
      const std::size_t nout = s.sendproc == MPI_PROC_NULL ? 0 : s.sendlist.size() * per;
      if (nout == 0) continue;
      double* const out = room(pair_send_[h], nout);
      double* o = out;
      for (int i : s.sendlist) {
        pack(i, s.shift, o);
        o += per;
      }
      MPI_Isend(out, static_cast<int>(nout), MPI_DOUBLE, s.sendproc, 30 + h, engine_.world, &req[nreq++]);
    }
    if (nreq == 0) continue;
    MPI_Waitall(nreq, req, MPI_STATUSES_IGNORE);
    for (int h = 0; h < 2; ++h) {
      const Swap& s = swaps_[k + h];
      const double* in = pair_recv_[h].data();
      const int n = static_cast<int>(nin[h] / per);
      for (int m = 0; m < n; ++m, in += per)
        unpack(s.firstrecv + m, in);
    }
  }
}

// The swaps backwards, a dimension's two at once: the ghosts' values go back
// along each swap and are added to the particles of its send list, the upper
// direction's before the lower one's as when the swaps ran one by one (the
// values sent come from ghosts of this dimension, which no send list of it
// holds, so adding one swap's values cannot change what the other sends).
template <class Pack, class Unpack>
void Comm::brick_reverse(int per, Pack pack, Unpack unpack) {
  for (std::size_t k = swaps_.size(); k >= 2; k -= 2) {
    MPI_Request req[4];
    int nreq = 0;
    std::size_t nin[2];
    for (int h = 0; h < 2; ++h) {
      const Swap& s = swaps_[k - 2 + h];
      nin[h] = s.sendproc == MPI_PROC_NULL ? 0 : s.sendlist.size() * per;
      if (nin[h] > 0)
        MPI_Irecv(room(pair_recv_[h], nin[h]), static_cast<int>(nin[h]), MPI_DOUBLE, s.sendproc, 40 + h,
                  engine_.world, &req[nreq++]);
    }
    for (int h = 0; h < 2; ++h) {
      const Swap& s = swaps_[k - 2 + h];
      const std::size_t nout = s.recvproc == MPI_PROC_NULL ? 0 : static_cast<std::size_t>(s.nrecv) * per;
      if (nout == 0) continue;
      double* const out = room(pair_send_[h], nout);
      double* o = out;
      for (int m = 0; m < s.nrecv; ++m, o += per)
        pack(s.firstrecv + m, o);
      MPI_Isend(out, static_cast<int>(nout), MPI_DOUBLE, s.recvproc, 40 + h, engine_.world, &req[nreq++]);
    }
    if (nreq == 0) continue;
    MPI_Waitall(nreq, req, MPI_STATUSES_IGNORE);
    for (int h = 1; h >= 0; --h) {
      const Swap& s = swaps_[k - 2 + h];
      if (nin[h] == 0) continue;
      const double* in = pair_recv_[h].data();
      for (int i : s.sendlist) {
        unpack(i, in);
        in += per;
      }
    }
  }
}

void Comm::forward_comm() {
  Particles& p = *engine_.particles;
  const int per = ghost_velocity ? 9 : 3;
  Vec3* const x = p.x.data();
  Vec3* const v = p.v.data();
  Vec3* const w = p.omega.data();
  const bool vel = ghost_velocity;
  const auto pack = [=](int i, const Vec3& shift, double* out) {
    for (int d = 0; d < 3; ++d)
      out[d] = x[i][d] + shift[d];
    if (vel) {
      for (int d = 0; d < 3; ++d) {
        out[3 + d] = v[i][d];
        out[6 + d] = w[i][d];
      }
    }
  };
  const auto unpack = [=](int j, const double* in) {
    x[j] = Vec3(in[0], in[1], in[2]);
    if (vel) {
      v[j] = Vec3(in[3], in[4], in[5]);
      w[j] = Vec3(in[6], in[7], in[8]);
    }
  };
  if (tiled())
    tiled_forward(per, pack, unpack);
  else
    brick_forward(per, pack, unpack);
}

void Comm::reverse_comm() {
  Particles& p = *engine_.particles;
  Vec3* const f = p.f.data();
  Vec3* const t = p.torque.data();
  const auto pack = [=](int j, double* out) {
    for (int d = 0; d < 3; ++d) {
      out[d] = f[j][d];
      out[3 + d] = t[j][d];
    }
  };
  const auto unpack = [=](int i, const double* in) {
    for (int d = 0; d < 3; ++d) {
      f[i][d] += in[d];
      t[i][d] += in[3 + d];
    }
  };
  if (tiled())
    tiled_reverse(6, pack, unpack);
  else
    brick_reverse(6, pack, unpack);
}

void Comm::forward_comm_field(std::vector<double>& data, int ncomp) {
  double* const a = data.data();
  const std::size_t n = static_cast<std::size_t>(ncomp);
  const auto pack = [=](int i, const Vec3&, double* out) { std::copy(a + i * n, a + (i + 1) * n, out); };
  const auto unpack = [=](int j, const double* in) { std::copy(in, in + n, a + j * n); };
  if (tiled())
    tiled_forward(ncomp, pack, unpack);
  else
    brick_forward(ncomp, pack, unpack);
}

void Comm::reverse_comm_field(std::vector<double>& data, int ncomp) {
  double* const a = data.data();
  const std::size_t n = static_cast<std::size_t>(ncomp);
  const auto pack = [=](int j, double* out) { std::copy(a + j * n, a + (j + 1) * n, out); };
  const auto unpack = [=](int i, const double* in) {
    for (std::size_t c = 0; c < n; ++c)
      a[i * n + c] += in[c];
  };
  if (tiled())
    tiled_reverse(ncomp, pack, unpack);
  else
    brick_reverse(ncomp, pack, unpack);
}

// ---- comm_style tiled -------------------------------------------------------

void Comm::alltoall_buffers(std::vector<std::vector<double>>& send, std::vector<std::vector<double>>& recv,
                            int tag) {
  const int n = engine_.nprocs, me = engine_.rank;
  recv.resize(static_cast<std::size_t>(n));
  std::vector<long long> scount(n, 0), rcount(n, 0);
  for (int r = 0; r < n; ++r)
    scount[r] = r == me ? 0 : static_cast<long long>(send[r].size());
  MPI_Alltoall(scount.data(), 1, MPI_LONG_LONG, rcount.data(), 1, MPI_LONG_LONG, engine_.world);
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
  alltoall_buffers(send, recv, 21);
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
  alltoall_buffers(send, recv, 22);
  for (int r = 0; r < n; ++r) {
    if (recv[r].empty()) continue;
    RecvPeer rp;
    rp.proc = r;
    rp.first = p.size();
    rp.count = p.unpack_borders(recv[r].data(), recv[r].size());
    trecv_.push_back(rp);
  }
}

// The ghosts' values of every step go straight to the ranks of the last
// ghost build, with the counts of that build; a rank's own periodic images
// are read from its send buffer. The buffers only grow (room()), so a step
// does not clear them again.
template <class Pack, class Unpack>
void Comm::tiled_forward(int per, Pack pack, Unpack unpack) {
  const int me = engine_.rank;  // (borders_tiled() gave both buffer sets a slot per rank)
  std::vector<MPI_Request> reqs;
  reqs.reserve(tsend_.size() + trecv_.size());
  for (const RecvPeer& rp : trecv_) {
    if (rp.proc == me) continue;
    const std::size_t m = static_cast<std::size_t>(rp.count) * per;
    reqs.emplace_back();
    MPI_Irecv(room(tbuf_recv_[rp.proc], m), static_cast<int>(m), MPI_DOUBLE, rp.proc, 23, engine_.world,
              &reqs.back());
  }
  for (const SendPeer& peer : tsend_) {
    const std::size_t m = peer.list.size() * static_cast<std::size_t>(per);
    double* const out = room(tbuf_send_[peer.proc], m);
    double* o = out;
    for (const Segment& seg : peer.segs) {
      for (int k = seg.begin; k < seg.end; ++k, o += per)
        pack(peer.list[k], seg.shift, o);
    }
    if (peer.proc == me) continue;
    reqs.emplace_back();
    MPI_Isend(out, static_cast<int>(m), MPI_DOUBLE, peer.proc, 23, engine_.world, &reqs.back());
  }
  MPI_Waitall(static_cast<int>(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  for (const RecvPeer& rp : trecv_) {
    const double* in = (rp.proc == me ? tbuf_send_ : tbuf_recv_)[rp.proc].data();
    for (int k = 0; k < rp.count; ++k, in += per)
      unpack(rp.first + k, in);
  }
}

// Back along the same routes: each rank's ghosts' values to their owners,
// added in the order of the send lists.
template <class Pack, class Unpack>
void Comm::tiled_reverse(int per, Pack pack, Unpack unpack) {
  const int me = engine_.rank;  // (borders_tiled() gave both buffer sets a slot per rank)
  std::vector<MPI_Request> reqs;
  reqs.reserve(tsend_.size() + trecv_.size());
  for (const SendPeer& peer : tsend_) {
    if (peer.proc == me) continue;
    const std::size_t m = peer.list.size() * static_cast<std::size_t>(per);
    reqs.emplace_back();
    MPI_Irecv(room(tbuf_recv_[peer.proc], m), static_cast<int>(m), MPI_DOUBLE, peer.proc, 24, engine_.world,
              &reqs.back());
  }
  for (const RecvPeer& rp : trecv_) {
    const std::size_t m = static_cast<std::size_t>(rp.count) * per;
    double* const out = room(tbuf_send_[rp.proc], m);
    double* o = out;
    for (int k = 0; k < rp.count; ++k, o += per)
      pack(rp.first + k, o);
    if (rp.proc == me) continue;
    reqs.emplace_back();
    MPI_Isend(out, static_cast<int>(m), MPI_DOUBLE, rp.proc, 24, engine_.world, &reqs.back());
  }
  MPI_Waitall(static_cast<int>(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  for (const SendPeer& peer : tsend_) {
    const double* in = (peer.proc == me ? tbuf_send_ : tbuf_recv_)[peer.proc].data();
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
