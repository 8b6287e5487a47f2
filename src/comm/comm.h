// MPI domain decomposition on a regular grid of ranks.
//
// Each rank owns the particles inside its subdomain. Ghosts (copies of
// particles within cutghost of the subdomain, including periodic images) are
// gathered in six swaps: -x, +x, then -y, +y including the x ghosts, then
// -z, +z, so corner neighbours arrive without diagonal messages. Each swap
// remembers what it sent, so every step only positions, velocities and spins
// travel forward, and forces and torques travel back in reverse order; the
// two swaps of a dimension travel at once (neither sends the other's ghosts).
// Subdomain boundaries are fractions of the box per dimension (`split`): the
// grid keeps its topology but its cut planes need not be equally spaced; the
// `balance` command and `fix balance` move them (src/comm/balance.h). Every
// rank holds the same cuts, and every subdomain is at least the ghost cutoff
// wide along each split or periodic dimension, so ghosts and forward/reverse
// communication only ever involve the adjacent rank.
//
// `comm_style tiled` (LAMMPS' name) lifts the grid: each rank owns a box of
// its own, all ranks know every box, particles migrate straight to the rank
// whose box holds them, and each ghost goes straight to every rank (and
// periodic image) within the ghost cutoff of whose box it lies, so no box
// needs to be wider than the cutoff and no box needs a fixed neighbour. The
// boxes are those of the grid until `balance ... rcb` or `fix balance ...
// rcb` replaces them by a recursive coordinate bisection (RcbNode): the box
// is cut in two, the ranks split in proportion, and each half cut again. The
// ownership of a point follows the tree's comparisons, so bounds, ownership
// and balancing agree to the last bit as on the grid.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/utils.h"
#include "core/vec3.h"

namespace granary {

class Engine;
class ContactHistory;

/// A node of the recursive bisection: a leaf names its rank; an inner node
/// cuts along `dim` at the fraction `cut` of the box, points below going to
/// child `lo`, the others to child `hi` (indices into the tree).
struct RcbNode {
  int rank = -1;  // >= 0: a leaf
  int dim = 0;
  double cut = 0.5;
  int lo = -1, hi = -1;
};

class Comm {
 public:
  explicit Comm(Engine& engine);

  enum class Style { kBrick, kTiled };
  Style style = Style::kBrick;
  bool tiled() const { return style == Style::kTiled; }
  /// Recursive-bisection boxes (comm_style tiled only); empty: the grid's boxes.
  const std::vector<RcbNode>& rcb_tree() const { return rcb_; }
  /// Replace the boxes by a bisection tree (every rank gets exactly one leaf;
  /// identical on every rank). Takes effect at the next setup().
  void set_rcb(std::vector<RcbNode> tree);
  void clear_rcb() { rcb_.clear(); }
  /// Bounds of rank r's subdomain (coordinates; the box faces exactly at its edges).
  void rank_box(int r, Vec3& lo, Vec3& hi) const;
  /// Coordinate of fraction f along d: boxlo + f * prd, the faces exactly at 0 and 1.
  double frac_coord(int d, double f) const;

  std::array<int, 3> user_grid{{0, 0, 0}};  // `processors`, 0 = automatic
  std::array<int, 3> procgrid{{1, 1, 1}};
  std::array<int, 3> myloc{{0, 0, 0}};
  std::array<std::array<int, 2>, 3> procneigh{};  // rank of the lower/upper neighbour per dim
  std::array<std::vector<double>, 3> split;       // procgrid[d]+1 fractions in [0, 1]
  bool ghost_velocity = true;                     // `communicate single vel yes`
  double cutghost_user = 0.0;
  double cutghost = 0.0;
  long long migrated_particles = 0;  // particles this rank sent away, since the engine started
  long long migrated_contacts = 0;   // contact-history entries that travelled with them
  int nlost = 0;                     // particles this rank removed at the last exchange (outside 'f' bounds)
  std::string first_lost;            // description of the first of them
  double lost_vmax = 0.0;            // the highest speed and the smallest radius among them
  double lost_rmin = 0.0;

  void processors_command(const Args& args);
  void modify_command(const Args& args);  // comm_modify / communicate
  void style_command(const Args& args);   // comm_style brick|tiled

  /// Choose the processor grid (first call) and set this rank's subdomain.
  void setup(double cutghost_needed);
  /// Move particles that left this subdomain to their new owners (with their
  /// contact history entries); particles outside a fixed box are lost.
  void exchange(ContactHistory* history);
  /// Build ghost particles from scratch.
  void borders();
  /// Copy x (with periodic shifts), v and omega of owned particles to their ghosts.
  void forward_comm();
  /// Sum f and torque of ghosts back onto their owners.
  void reverse_comm();
  /// Forward communication of an extra per-particle field (ncomp doubles each).
  void forward_comm_field(std::vector<double>& data, int ncomp);
  /// Reverse communication (sum) of an extra per-particle field.
  void reverse_comm_field(std::vector<double>& data, int ncomp);

  /// Position of cut plane k (0..procgrid[d]) along d for the fractions `cuts`
  /// (the current `split[d]` by default): boxlo + cuts[k] * prd, the last one
  /// exactly boxhi. Subdomain bounds, ownership and balancing all use it, so
  /// they agree to the last bit.
  double cut_coord(int d, int k, const std::vector<double>& cuts) const;
  double cut_coord(int d, int k) const { return cut_coord(d, k, split[d]); }
  /// Grid index along d of coordinate x for the fractions `cuts`: the slab k
  /// with cut k <= x < cut k+1 (points beyond the box go to the end slabs).
  int slab_of(int d, double x, const std::vector<double>& cuts) const;
  /// Rank owning a point under the current cuts.
  int owner_of(const Vec3& x) const;
  /// Rank at grid location (ix, iy, iz) (x fastest).
  int rank_at(int ix, int iy, int iz) const { return ix + procgrid[0] * (iy + procgrid[1] * iz); }
  /// Throw InputError unless every slab of `cuts` along d is at least `width`
  /// wide (checked for dimensions that are split or periodic; identical on
  /// every rank since the cuts are).
  void check_widths(const std::array<std::vector<double>, 3>& cuts, double width,
                    const std::string& advice) const;

 private:
  struct Swap {
    int dim = 0, dir = 0;  // dir 0: send to lower neighbour, 1: upper
    int sendproc = -1, recvproc = -1;
    bool active = false;
    Vec3 shift{0, 0, 0};  // periodic shift applied to sent positions
    std::vector<int> sendlist;
    int firstrecv = 0, nrecv = 0;
  };
  void choose_grid();
  void set_subdomain();
  // comm_style tiled: direct messages to every rank concerned
  struct Segment {
    Vec3 shift{0, 0, 0};
    int begin = 0, end = 0;  // range of SendPeer::list sent with this periodic shift
  };
  struct SendPeer {
    int proc = 0;
    std::vector<int> list;
    std::vector<Segment> segs;
  };
  struct RecvPeer {
    int proc = 0;
    int first = 0, count = 0;  // ghosts first .. first+count-1 came from proc
  };
  void exchange_tiled(ContactHistory* history);
  void borders_tiled();
  /// Send per-proc buffers (doubles) to their procs and receive from every
  /// proc that sends here, the counts exchanged first (migration, ghost
  /// builds). The buffer for this rank itself is moved, not sent. All send
  /// buffers are empty on return (their capacity kept).
  void alltoall_buffers(std::vector<std::vector<double>>& send, std::vector<std::vector<double>>& recv,
                        int tag);
  template <class Pack, class Unpack>
  void tiled_forward(int per, Pack pack, Unpack unpack);
  template <class Pack, class Unpack>
  void tiled_reverse(int per, Pack pack, Unpack unpack);
  std::vector<RcbNode> rcb_;
  std::vector<std::array<double, 3>> rcb_lo_, rcb_hi_;  // every rank's box as fractions of the box
  std::vector<SendPeer> tsend_;
  std::vector<std::vector<double>> tbuf_send_, tbuf_recv_;
  std::vector<RecvPeer> trecv_;
  template <class Pack, class Unpack>
  void brick_forward(int per, Pack pack, Unpack unpack);
  template <class Pack, class Unpack>
  void brick_reverse(int per, Pack pack, Unpack unpack);
  Engine& engine_;
  std::vector<Swap> swaps_;
  std::vector<double> sendbuf_;
  std::array<std::vector<double>, 2> pair_send_, pair_recv_;  // a dimension's two swaps
  bool grid_set_ = false;
};

}  // namespace granary
