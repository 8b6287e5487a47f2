// The multiple-contact model of Brodu, Dijksman
// and Behringer (Phys. Rev. E 91, 032201, 2015) for soft spheres, used with
// the contact model word "surface multicontact" (pair_style gran, fix
// wall/gran). Each contact of a sphere deforms it like a point force on an
// elastic half-space (Boussinesq); the contact i-j then sees i's radius
// changed by the displacement that i's other contacts cause at the i-j
// contact point, along its normal:
//
//   delta_{ij<-ik} = -gamma (1 + nu) F_ik / (2 pi Y d) *
//       [ (n_ik.u)(n_ij.u) + (3 - 4 nu) n_ik.n_ij - (1 - 2 nu) (n_ik + u).n_ij / (1 + n_ik.u) ]
//
// with n the inward normals of i at the contact points, u the unit vector and
// d the distance from contact point ik to contact point ij, F_ik the normal
// force of contact ik, Y and nu of i's type, gamma the geometric prefactor.
// The overlap of contact i-j grows by the sum over k != j of i's terms plus the
// sum over l != i of j's (a wall is rigid: no term of its own).
//
// The forces and points are those of the previous force evaluation: every
// contact loop records, per particle, its contacts (partner, contact point
// relative to the centre, inward normal, |F_n|) into a buffer; after the
// evaluation the buffer becomes the per-particle field "multicontact", which
// migrates with the particles, goes to restart files, and is sent to ghosts
// before the next evaluation. The forces of a run's setup leave it as it was
// (it is contact history). fix multicontact/halfspace owns one MultiContact;
// Force points to it. The formulas and choices: doc/fixes/multicontact_halfspace.md.
#pragma once

#include <string>
#include <vector>

#include "core/vec3.h"

namespace granary {

class Engine;
class Particles;

class MultiContact {
 public:
  /// Contacts recorded per particle, and doubles per record: partner key,
  /// contact point minus the centre (3), inward normal (3), |F_n|.
  static constexpr int kSlots = 24, kRecord = 8, kStride = 1 + kSlots * kRecord;

  /// `owner` names the fix in messages; registers the per-particle field.
  MultiContact(Engine& engine, const std::string& owner, double gamma);
  /// Free the per-particle field (the fix was unfixed).
  void release();
  /// Young's modulus and Poisson's ratio per type (index 1..ntypes).
  void set_materials(std::vector<double> youngs, std::vector<double> poisson);

  /// Before the contacts of a force evaluation (Update::compute_forces): the
  /// records of the last evaluation go to the ghosts; the buffer is emptied.
  void begin();
  /// After the evaluation (pair and walls): the buffer becomes the field.
  void finish();

  /// The change of the radius of particle i at its contact at `point` (inward
  /// normal n_in) caused by i's recorded contacts other than `exclude`.
  double shift(const Particles& p, int i, double exclude, const Vec3& point, const Vec3& n_in) const;
  /// Record a contact of owned particle i for the next evaluation.
  void record(const Particles& p, int i, double key, const Vec3& rel_point, const Vec3& n_in, double fn);

  /// A contact's point relative to the centre of a sphere of radius r: the
  /// middle of the (geometric) overlap, along the normal n pointing into it.
  static Vec3 offset(double r, double overlap, const Vec3& n) { return -(r - 0.5 * overlap) * n; }

  /// The key of a wall contact: wall fix `ordinal` (0, 1, ...), mesh element
  /// `element` (0 for a primitive wall). Negative: particle ids are positive.
  static double wall_key(int ordinal, long long element) {
    return -(static_cast<double>(ordinal + 1) * 1099511627776.0 + static_cast<double>(element));
  }
  /// A number for each wall fix that records contacts (its key's ordinal).
  int wall_ordinal(const std::string& fix_id);

  const std::string& owner() const { return owner_; }

 private:
  Engine& engine_;
  std::string owner_;
  double gamma_;
  int field_ = -1;
  std::vector<double> youngs_, poisson_;  // per type (1-based)
  std::vector<double> next_;              // this evaluation's records, kStride per owned particle
  int nnext_ = 0;                         // owned particles the buffer covers
  std::vector<std::string> walls_;
};

}  // namespace granary
