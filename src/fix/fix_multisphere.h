// fix multisphere: rigid clumps of spheres (LIGGGHTS syntax).
//
//   fix ID group multisphere [allow_group_and_set yes|no] [allow_heatsource yes|no]
//
// Sub-spheres are ordinary particles whose `body` field is the body id; they
// migrate and are ghosted like any particle. Every rank keeps a record of
// every body (Bodies), but advances only the bodies with a sub-sphere it owns
// (its active bodies): each step it takes the force and torque of each owned
// sub-sphere, exchanges them only for the bodies whose sub-spheres are owned
// by several ranks (with just those ranks), sums them per body in sub-sphere
// order (the same additions on any number of ranks), and
// places its own sub-spheres (ghosts follow by forward communication). A rank
// that gains a sub-sphere of a body it did not advance fetches the body's
// state at the neighbour-list rebuild; outputs and restarts bring every record
// up to date collectively (sync_bodies). Centre of mass: velocity Verlet.
// Rotation: the NO_SQUISH symplectic splitting of the free rotor (Miller et
// al. 2002), in quaternion form. See doc/fixes/multisphere.md and
// doc/multisphere_design.md.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "fix/fix.h"
#include "fix/fix_particle_template.h"
#include "particles/bodies.h"
#include "particles/clumps.h"

namespace granary {

class Modify;

class FixMultisphere : public Fix, public BodyRegistrar, public Clumps {
 public:
  FixMultisphere(Engine& engine, const Args& args);
  ~FixMultisphere() override;
  unsigned hooks() const override { return INITIAL_INTEGRATE | PRE_NEIGHBOR | FINAL_INTEGRATE; }

  void init() override;
  void setup() override;
  void initial_integrate() override;
  void pre_neighbor() override;
  void final_integrate() override;
  double compute_scalar() override { return bodies_.size(); }

  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

  /// BodyRegistrar: record a body (every rank, identical arguments). Its
  /// sub-spheres (ids first_id + k) are taken over at the next placement.
  void add_body(tagint body_id, tagint first_id, const TemplateParticle& particle, const Vec3& x_cm,
                const Eigen::Quaterniond& q, const Vec3& v, const Vec3& omega) override;

  /// Smallest body id above every id in use (collective).
  tagint next_body_id();
  /// Create one clump from `particle` with its centre of mass at x (collective;
  /// the `create_clump` command). Returns the body id.
  tagint create_clump(const TemplateParticle& particle, const Vec3& x, const Eigen::Quaterniond& q,
                      const Vec3& v, const Vec3& omega) override;
  BodyRegistrar& registrar() override { return *this; }
  /// Remove every body that lost a sub-sphere (delete_atoms, particles lost
  /// through a fixed boundary) together with its remaining sub-spheres
  /// (collective; particles must have no ghosts or ghosts are rebuilt by the
  /// caller). Returns the number of bodies removed.
  long long remove_incomplete_bodies();
  /// Remove the clumps with these body ids: their owned sub-spheres (with
  /// their contact-history rows) and their body records. Called on every rank
  /// with the same ids, when there are no ghosts (pre_exchange, between runs);
  /// unknown ids are ignored. Returns the number of particles removed on this
  /// rank (the caller updates the global count).
  long long remove_bodies(const std::vector<tagint>& ids) override;
  /// Break the clumps with these body ids: their sub-spheres become free
  /// spheres with the velocity and angular velocity they had, and the body
  /// records go. Called on every rank with the same ids, when there are no
  /// ghosts (pre_exchange); unknown ids are ignored. Returns the number of
  /// bodies broken.
  long long release_bodies(const std::vector<tagint>& ids);

  /// The body records. The dynamic state (xcm, vcm, angmom, omega, quat, fcm,
  /// torque) of a body is current on the ranks that own one of its
  /// sub-spheres (Bodies::current); call sync_bodies() first (collective) to
  /// read it for every body.
  const Bodies& bodies() const override { return bodies_; }
  Bodies& bodies() override { return bodies_; }
  /// Make every rank's record of every body current (collective; cheap when
  /// nothing moved since the last call).
  void sync_bodies() override;
  /// Body states this rank received from others because sub-spheres migrated
  /// to it (since the fix was defined).
  long long fetched_states() const { return fetched_; }
  /// Bodies this rank shares with other ranks (partial force sums exchanged each step).
  int shared_bodies() const { return static_cast<int>(shared_.size()); }
  /// Body centre wrapped into the periodic box [m].
  Vec3 wrapped_centre(int b) const override;

  /// One NO_SQUISH step of a torque-free rotor: rotates q (body -> space) and
  /// the body-frame angular momentum lb for time dt with principal moments
  /// `inertia` (sequence axes 3, 2, 1, 2, 3 with dt/2, dt/2, dt, dt/2, dt/2).
  static void rotate_free(Eigen::Quaterniond& q, Vec3& lb, const Vec3& inertia, double dt);

 private:
  void find_fields();
  /// Tell the outputs (BodyOutput) the current number of bodies.
  void bodies_changed();
  /// Take over sub-spheres not yet placed (index field 0): index, mass, image.
  void resolve_new_spheres();
  /// body_mass of every particle (owned and ghost) from the replicated bodies.
  void fill_body_mass();
  void compute_rotations();
  /// Set x (optionally), v and omega of the owned sub-spheres from their bodies.
  void place_spheres(bool positions);
  /// fcm and torque of every active body: the sum of its sub-spheres' forces
  /// and torques in sub-sphere index order (those of shared bodies exchanged
  /// with the ranks sharing them first), so the same on any decomposition.
  void sum_forces();
  void sum_forces_runs();  ///< sum_forces() along runs_
  /// After the owned particles or the bodies changed (collective): the active
  /// bodies, their missing state (fetch_state), their rotation matrices, the
  /// per-particle caches and the sharing pattern (find_partners).
  void reindex();
  /// Fetch the current state of active bodies whose record is not current
  /// from a rank where it is (collective).
  void fetch_state();
  /// Which other ranks own sub-spheres of the bodies this rank shares (collective).
  void find_partners();
  /// Body index and sub-sphere index of owned particle i (-1 when free).
  int body_of(int i, int& k) const;
  /// Fill the per-particle caches (body index, slot) of the owned particles
  /// from the body field, and the runs and slots of the active bodies.
  void index_spheres();
  /// shape_start_ of every body (after the bodies changed).
  void find_shapes();
  /// Body-frame offset of owned sub-sphere i of body b when it has a slot.
  const Vec3& slotted_offset(int i, int b) const {
    return bodies_.offsets[shape_start_[b] + pslot_[i] - slot_[b]];
  }
  /// reindex() when bodies or particles changed (collective flag), index_spheres()
  /// when only the number of owned particles differs from the caches.
  void check_index();
  /// Space-frame angular velocity of body b from its angular momentum and rot_[b].
  Vec3 omega_from(int b) const;
  Vec3 omega_from(const Eigen::Matrix3d& r, int b) const;  ///< the same with the rotation matrix r of b

  Bodies bodies_;
  // Rotation matrix of each body at the current step, set before the
  // sub-spheres are placed and kept until the next step: the space-frame
  // offset (lever arm) of sub-sphere k of body b is rot_[b] * d_k, computed
  // where needed (placing, summing), not stored.
  std::vector<Eigen::Matrix3d> rot_;
  // Per owned particle, valid from one neighbour-list build (pre_neighbor,
  // where particles are reordered) to the next: the body index (-1: free
  // sphere or not yet taken over) and the sub-sphere's slot in part_ (-1:
  // summed along its body's run; sub-sphere k of body b in a slot has
  // pslot_ = slot_[b] + k).
  std::vector<int> pbody_, pslot_;
  std::vector<int> slotted_spheres_;  // the owned particles with a slot (pslot_ >= 0), ascending
  // Per body: where its offsets in the body frame begin in Bodies::offsets,
  // those of the first body with the same offsets, bit for bit (bodies of one
  // template share them): placing and summing read a small table per
  // template, not each body's copy. Set by find_shapes() when shapes_stale_.
  std::vector<int> shape_start_;
  bool shapes_stale_ = true;
  // Force and torque of each sub-sphere of the active bodies (6 doubles per
  // slot; body b's sub-sphere k in slot slot_[b] + k, set from one reindex()
  // to the next; zero where another rank owns the sub-sphere).
  std::vector<int> slot_;
  std::vector<double> part_;
  // The active bodies with sub-spheres this rank does not own (their slots
  // are zeroed before each sum; every other slot is written by its sub-sphere).
  std::vector<int> partial_;
  // The active bodies whole on this rank whose sub-spheres lie at
  // consecutive indices in sub-sphere order (as after a spatial sort): the
  // first index of each one's run (runs_); their sums go along the runs, the
  // same additions in the same order as through the slots. The other active
  // bodies, ascending (slotted_), are summed through the slots.
  std::vector<int> runs_, slotted_;
  // Active bodies: indices of the bodies with an owned, taken-over sub-sphere,
  // ascending; is_active_ per body. Fixed from one reindex() to the next.
  std::vector<int> active_;
  std::vector<char> is_active_;
  // Force exchange for bodies whose sub-spheres are owned by several ranks.
  // One Partner per other rank sharing bodies with this one; `bodies` are
  // the shared body indices in ascending order (the same order on both sides),
  // whose sub-sphere slots (6 doubles per sub-sphere) are sent and received,
  // body m's from start[m] on.
  struct Partner {
    int rank = -1;
    std::vector<int> bodies, start;
    std::vector<double> send, recv;
  };
  std::vector<Partner> partners_;
  // Shared bodies (ascending) and, per shared body, the other ranks owning
  // some of its sub-spheres (CSR): partner index and the body's position in
  // that partner's list. Each sub-sphere is owned by one rank, so merging
  // the received slots into this rank's (zeros elsewhere) is exact.
  std::vector<int> shared_, shared_start_;
  std::vector<std::pair<int, int>> shared_src_;
  bool reindex_ = true;     // bodies or particles changed: reindex() before the next use
  bool invalidate_ = true;  // mark inactive records not current at the next step
  long long fetched_ = 0;   // see fetched_states()
  bool stale_ = false;      // some rank's records of inactive bodies are out of date
  int index_field_ = -1;    // per-particle sub-sphere index + 1 (0: not yet placed)
  int mass_field_ = -1;     // per-particle body mass (read by contact models)
  bool pending_ = false;    // bodies added whose sub-spheres were not yet taken over
};

}  // namespace granary
