// Per-particle storage as a structure of arrays.
//
// Owned particles occupy [0, nlocal), ghosts (copies of particles owned by
// other ranks or periodic images) occupy [nlocal, nlocal + nghost). Every field
// states whether it is sent to ghosts each step (forward), summed back from
// ghosts (reverse), carried when a particle migrates (exchange) and written to
// restarts. Fixes that need extra per-particle values register them with
// add_field() and get the same treatment.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace granary {

using tagint = std::int64_t;

/// An extra per-particle field registered by a style (e.g. a body id or a fix's state).
struct ExtraField {
  std::string name;
  int ncomp = 1;
  bool ghost = false;        // copied to ghosts when they are built (borders)
  bool exchange = true;      // migrates with the particle
  bool history = false;      // contact history: not advanced by the force pass at run setup
  bool restart = true;       // written to restart files (fields that migrate only)
  bool settable = false;     // a property the set command may write (fix property/atom)
  std::vector<double> init;  // values of a new particle (add_local), ncomp of them; empty: zeros
  std::vector<double> data;  // ncomp values per particle
};

/// Extra fields read by styles other than the one that registers them, by a
/// FieldRef obtained once at set-up (never a name looked up in a loop):
/// the mass of the clump a sub-sphere belongs to (0 for a free sphere),
/// registered and kept current by fix multisphere, read by the contact loops.
inline constexpr const char* kBodyMassField = "body_mass";

class Particles {
 public:
  Particles();

  int nlocal = 0;
  int nghost = 0;
  int ntypes = 0;
  /// Most atom types a box may have (per-type-pair tables grow as its square).
  static constexpr int kMaxTypes = 10000;
  tagint natoms = 0;  // global number of particles (kept current by the owner of the count)
  /// atom_style sph: point particles (radius 0 until pair_style sph/... sets
  /// it to the smoothing length) with a per-type mass (the mass command) and
  /// the per-particle fields sph_rho, sph_p, sph_drho
  bool sph = false;
  /// Switch atom_style sph on (adding its fields) or off (releasing them).
  void set_sph(bool on);
  std::vector<double> type_mass;  // [type]; 0 = not set (atom_style sph)
  std::string sph_kernel;         // `set ... sphkernel NAME`: the kernel the SPH fixes expect

  // core fields: [exchange, restart]; x v omega are forward-communicated;
  // f torque are reverse-communicated (newton on).
  std::vector<tagint> id;
  std::vector<int> type;
  std::vector<int> mask;  // group bits; bit 0 = group "all"
  std::vector<Vec3> x, v, f, omega, torque;
  std::vector<double> radius, density, rmass;
  std::vector<tagint> body;  // clump id, -1 for a free sphere
  std::vector<int> image;    // periodic image flags packed 10 bits per dimension

  int size() const { return nlocal + nghost; }
  /// The largest radius of the owned particles of every rank (collective
  /// over `world`); 0 with no particles.
  double max_radius(MPI_Comm world) const;
  /// Resize every field to hold n particles (owned + ghost).
  void resize(int n);
  /// Append an owned particle (only when there are no ghosts). Returns its index.
  int add_local(tagint id_, int type_, const Vec3& x_, double radius_, double density_);
  /// Set the extra fields of slot i to the values of a new particle (each
  /// field's `init`, zeros when it has none).
  void init_extras(int i);
  /// Copy particle `from` over slot `to` (all fields incl. extras).
  void copy(int from, int to);
  /// Remove owned particle i by moving the last owned one into its slot (ghosts are dropped).
  void remove_local(int i);
  /// Remove all ghosts.
  void clear_ghosts();
  /// Reorder the owned particles (no ghosts present): new slot k takes old slot order[k].
  void permute(const std::vector<int>& order);

  /// Migration record of particle i (all fields that migrate).
  void pack_exchange(int i, std::vector<double>& buf) const;
  /// Append an owned particle from a buffer written by pack_exchange; returns doubles read.
  int unpack_exchange(const double* buf);

  /// Ghost record (everything a neighbour rank needs to compute contacts),
  /// with the position shifted by a periodic image.
  void pack_border(int i, const Vec3& shift, std::vector<double>& buf) const;
  /// Append the ghosts of a buffer of n doubles written by pack_border (all
  /// records of one length: the core values and the fields marked `ghost`,
  /// alike on every rank); the arrays grow once. Returns the ghosts appended.
  int unpack_borders(const double* buf, std::size_t n);

  // id -> local index map (owned copies win over ghosts); -1 when absent.
  void map_build(tagint max_id);
  int map(tagint tag) const { return (tag >= 0 && tag < static_cast<tagint>(map_.size())) ? map_[tag] : -1; }
  void map_clear();
  /// Largest id anywhere (collective over the engine's ranks is done by the caller).
  tagint max_local_id() const;

  /// Register an extra field; returns its index in `extras`. Re-registering a name returns the existing one.
  int add_field(const std::string& name, int ncomp, bool ghost, bool exchange);
  /// Free the storage of field `name` (its owner was unfixed). The slot stays,
  /// empty, nameless and neither communicated nor written to restart files, so
  /// the indices other styles hold stay valid; a later add_field of the same
  /// name starts a new field. Unknown names are ignored.
  void release_field(const std::string& name);
  int find_field(const std::string& name) const;
  std::vector<ExtraField> extras;

  /// Mass of particle i from radius and density (sphere).
  static double sphere_mass(double radius, double density);

  // image flags
  static int image_pack(int ix, int iy, int iz);
  static void image_unpack(int image, int& ix, int& iy, int& iz);

 private:
  static constexpr int kCoreValues = 16;  // doubles written by pack_core
  void pack_core(int i, const Vec3& shift, std::vector<double>& buf) const;
  int unpack_core(int i, const double* buf);
  void pack_extras(int i, bool ExtraField::*flag, std::vector<double>& buf) const;
  int unpack_extras(int i, bool ExtraField::*flag, const double* buf);
  std::vector<int> map_;
};

/// A registered extra field, found once by name (at a style's init) and read
/// by index after: data() is the field's values, nullptr when no style has
/// registered the field (or it was released).
class FieldRef {
 public:
  FieldRef() = default;
  FieldRef(const Particles& p, const char* name) : index_(p.find_field(name)) {}
  double* data(Particles& p) const {
    return index_ >= 0 && !p.extras[index_].data.empty() ? p.extras[index_].data.data() : nullptr;
  }
  const double* data(const Particles& p) const {
    return index_ >= 0 && !p.extras[index_].data.empty() ? p.extras[index_].data.data() : nullptr;
  }

 private:
  int index_ = -1;
};

}  // namespace granary
