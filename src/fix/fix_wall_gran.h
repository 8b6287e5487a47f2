// fix wall/gran with primitive walls (LIGGGHTS syntax):
//   fix ID group wall/gran model hertz tangential history [rolling_friction cdt]
//       primitive type T xplane|yplane|zplane POS
//   fix ID group wall/gran ... primitive type T zcylinder RADIUS CX CY
//   fix ID group wall/gran model hertz tangential history [rolling_friction cdt]
//       mesh n_meshes N meshes M1 M2 ...
// The wall is a material of atom type T (its Young's modulus, Poisson ratio
// and the pair coefficients of T with each particle type apply). Contact
// history is kept per particle per wall and migrates with the particle. Mesh
// walls (fix mesh/surface) keep contact slots keyed by triangle: two per
// particle in a per-particle field, and the further ones of the few particles
// that touch more than two triangles (in corners) in a table by particle id;
// see doc/architecture.md for how the contacts of a sphere with neighbouring
// triangles are reduced to the physical ones.
#pragma once

#include "contact/contact_model.h"
#include "core/vec3.h"
#include "fix/fix.h"
#include "pair/materials.h"
#include "particles/particles.h"

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace granary {

class MultiContact;

class FixMeshSurface;

class FixWallGran : public Fix {
 public:
  FixWallGran(Engine& engine, const Args& args);
  unsigned hooks() const override { return POST_FORCE | POST_NEIGHBOR | (mesh_ ? PRE_EXCHANGE : 0u); }
  /// Mesh form: the extra contact slots (beyond the per-particle ones) of all
  /// ranks are handed round before particles migrate; each rank keeps those
  /// of its particles at the next post_neighbor.
  void pre_exchange() override;
  /// Mesh form: the extra contact slots of every rank go into the restart file.
  void prepare_restart() override;
  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;
  /// List the particles that can reach the wall before the next
  /// neighbour-list build (mesh walls: while the meshes do not move).
  void post_neighbor() override;
  void init() override;
  void post_force() override;
  void setup() override {}
  /// Contact history of this wall goes with it.
  void unfixed() override;
  /// Mesh form: total force of the particles on the meshes (x, y, z), summed over ranks [N].
  double compute_vector(int i) override;

  /// Mesh walls: contact slots per particle in the per-particle field, most
  /// contacts one particle may have, and doubles per slot before the contact
  /// history (triangle key, contact point x y z).
  static constexpr int kInlineSlots = 1;
  static constexpr int kMeshSlots = 32;
  static constexpr int kSlotHeader = 4;

  /// Signed distance-based contact with the primitive: overlap and unit normal
  /// pointing from the wall to the particle centre. Returns false without contact.
  bool contact(const Vec3& x, double r, double& overlap, Vec3& n) const;

  enum class Shape { XPlane, YPlane, ZPlane, ZCylinder };
  /// Mesh form (fix mesh/surface walls): contact() does not apply.
  bool mesh_form() const { return mesh_; }

  /// One contact of a particle with the wall, as compute wall/gran/local
  /// reports it.
  struct LocalContact {
    int i = -1;                   ///< local index of the particle
    int mesh = -1;                ///< the mesh's position in this fix's list (-1: primitive wall)
    int tri = -1;                 ///< triangle of that mesh, in the order of its file (-1: primitive)
    Vec3 point, wall_v;           ///< contact point on the wall surface, the wall's velocity there
    Vec3 n;                       ///< unit normal from the wall to the particle centre
    double overlap = 0.0;         ///< radius minus the distance of the centre from the wall
    contact::ContactResult res;   ///< force and torque of the contact on the particle
    std::vector<double> history;  ///< the contact's history as stored (history_size() values)
  };
  /// The contacts of the owned particles in `bits` (and in this fix's group)
  /// with the wall, found as post_force finds them, with the force of the
  /// contact model for the current positions, velocities and spins and the
  /// contact history stored at the last force evaluation, which is not
  /// advanced. Needs init() (the materials and meshes): throws an InputError
  /// naming `who` before the first run.
  void local_contacts(int bits, const std::string& who, std::vector<LocalContact>& out) const;
  /// Doubles of contact history per contact.
  int history_size() const { return nhist_; }
  /// Mesh form: the number of meshes.
  int nmeshes() const { return static_cast<int>(mesh_ids_.size()); }

 private:
  contact::ModelSpec spec_;
  MaterialTable materials_;
  Shape shape_ = Shape::ZPlane;
  int wall_type_ = 1;
  double pos_ = 0.0;  // plane position
  double cyl_r_ = 0.0, cyl_cx_ = 0.0, cyl_cy_ = 0.0;
  int field_ = -1;  // per-particle history field
  // mesh form: number of occupied contact slots per particle, a dense field so
  // that particles away from the mesh skip their (large) slot rows entirely
  int count_field_ = -1;
  FieldRef body_mass_;  // clump mass of each sub-sphere (fix multisphere), found at init
  std::string count_name_;
  int nhist_ = 0;
  std::string field_name_;

  // particles within reach of the wall (see post_neighbor)
  std::vector<int> near_;
  std::int64_t near_build_ = -1;  // Neighbor::nbuilds when near_ was made; -1: none
  std::vector<long long> moves_;  // mesh form: TriMesh::moves() of each mesh when near_ was made
  /// Whether near_ holds every particle that can touch the wall now.
  bool near_current() const;
  void list_near_mesh();

  // mesh form: slots kInlineSlots.. of the particles with more contacts, by
  // particle id (slot data only, count = the particle's count - kInlineSlots)
  std::unordered_map<std::int64_t, std::vector<double>> extra_;
  // (id, count, slots) records handed round before migration or read from a
  // restart file, kept for the particles this rank owns at post_neighbor
  std::vector<double> incoming_;
  std::vector<double> restart_extra_;  // all ranks' records, for pack_restart
  void adopt_extra();
  /// A restart file written with another number of inline slots: its field
  /// is moved into this layout (slots beyond kInlineSlots into extra_).
  void convert_inline_slots();
  void pack_extra(std::vector<double>& out) const;
  /// Clear all slots of particle i (inline and extra).
  void clear_slots(int i, double* hist, double* count);
  /// Distance from the particle centre to the wall surface (>= 0).
  double gap(const Vec3& x) const;

  // mesh form
  void post_force_mesh();
  /// A contact of a sphere with a mesh triangle (see post_force_mesh).
  struct Candidate {
    int mesh, tri;
    bool face;
    double overlap;
    Vec3 point, n;
  };
  static constexpr int kMaxCandidates = 64;
  /// The contacts a sphere (centre x, radius r, particle id tag) has with the
  /// meshes: writes the candidates to cand and the indices of the physical
  /// ones to kept (both kMaxCandidates long); returns the number kept.
  int mesh_contacts(const Vec3& x, double r, tagint tag, Candidate* cand, int* kept) const;
  bool initialized_ = false;  // init() has run: materials and meshes resolved
  /// "surface multicontact": the fix that changes the overlaps, and this
  /// wall's number in its contact keys
  MultiContact* mc_ = nullptr;
  int mc_ordinal_ = 0;
  bool mesh_ = false;
  std::vector<std::string> mesh_ids_;
  std::vector<FixMeshSurface*> meshes_;  // resolved by init
  std::vector<int> key_base_;            // triangle keys of mesh m start at key_base_[m] + 1
  double force_[3] = {0, 0, 0};          // on the meshes, this rank, last step
};

}  // namespace granary
