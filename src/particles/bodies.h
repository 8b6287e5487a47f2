// Rigid bodies (clumps of spheres) as a structure of arrays.
//
// Every rank holds a record of every body (ids, mass properties, sub-sphere
// offsets: identical everywhere), but a rank advances only the bodies with a
// sub-sphere it owns, so the dynamic state (centre, velocities, orientation,
// forces) of the other records may be out of date (`current`); fix
// multisphere brings them up to date when needed (FixMultisphere::sync_bodies).
// The sub-spheres are ordinary particles whose `body` field is the body id. Bodies are kept sorted by id, so
// their order does not depend on the number of ranks. The body frame is the principal frame: the principal
// moments are `inertia` (ascending, so body axis x is the long axis of an elongated body) and a vector d in
// the body frame is R(quat) d in space.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "particles/particles.h"

namespace granary {

class Bodies {
 public:
  int size() const { return static_cast<int>(tag.size()); }

  // ---- per-body arrays (index b in [0, size()))
  std::vector<tagint> tag;               // body id (the `body` field of its sub-spheres)
  std::vector<tagint> first_id;          // particle id of sub-sphere 0 when created
  std::vector<int> type;                 // atom type of the sub-spheres
  std::vector<int> nspheres;             // number of sub-spheres
  std::vector<int> sphere_start;         // size()+1 offsets into `offsets` / `radii`
  std::vector<double> mass;              // [kg]
  std::vector<double> volume;            // solid volume [m^3]
  std::vector<double> density;           // [kg/m^3]
  std::vector<double> bounding_radius;   // [m]
  std::vector<Vec3> inertia;             // principal moments [kg m^2]
  std::vector<Vec3> xcm;                 // centre of mass, unwrapped across periodic boundaries [m]
  std::vector<Vec3> vcm;                 // centre-of-mass velocity [m/s]
  std::vector<Vec3> angmom;              // angular momentum about the centre, space frame [kg m^2/s]
  std::vector<Vec3> omega;               // angular velocity, space frame (follows angmom and quat) [1/s]
  std::vector<Eigen::Quaterniond> quat;  // body frame -> space frame
  std::vector<Vec3> fcm;                 // total force of the last force evaluation [N]
  std::vector<Vec3> torque;              // total torque about the centre, space frame [N m]
  /// 1 when this rank's copy of the dynamic state (xcm, vcm, angmom, omega,
  /// quat, fcm, torque) is the body's current state. Set by add and unpack.
  std::vector<char> current;

  // ---- per-sub-sphere arrays (CSR: sphere_start[b] .. sphere_start[b+1])
  std::vector<Vec3> offsets;  // sub-sphere centres in the body frame [m]
  std::vector<double> radii;  // [m]
  /// Share of the body mass each sub-sphere carries (its rmass / body mass):
  /// about r^3 / sum r^3, adjusted so that the shares sum to 1 and their first
  /// moment about the centre of mass vanishes. What the adjustment cannot remove
  /// (directions the offsets do not span, e.g. the integration error of a
  /// dumbbell's centre across its axis) is removed by moving the body origin
  /// to the shares' centre when the body is added. Body forces applied per
  /// particle in proportion to rmass (gravity) then sum to M g with no torque.
  std::vector<double> mass_share;

  /// Add a body (kept sorted by id); returns its index. Throws std::invalid_argument
  /// when the id is already used or the data is inconsistent.
  int add(tagint id, tagint first, int atom_type, double m, double vol, double rho, const Vec3& moments,
          const std::vector<Vec3>& body_offsets, const std::vector<double>& body_radii, const Vec3& x,
          const Eigen::Quaterniond& q, const Vec3& v, const Vec3& w);
  /// Remove the bodies whose `doomed` entry is non-zero (one pass, order kept).
  void remove(const std::vector<char>& doomed);
  void clear();

  /// Index of body `id`, -1 when unknown.
  int find(tagint id) const {
    if (dense_) return (id >= 0 && id < static_cast<tagint>(index_.size())) ? index_[id] : -1;
    return find_sorted(id);
  }
  tagint max_tag() const { return tag.empty() ? 0 : tag.back(); }
  long long total_spheres() const { return offsets.size(); }

  Eigen::Matrix3d rotation(int b) const { return quat[b].toRotationMatrix(); }
  /// Space-frame angular velocity from angmom and quat: R I^-1 R^T L.
  Vec3 omega_from_angmom(int b) const;
  /// Space-frame angular momentum of spin w: R I R^T w.
  Vec3 angmom_from_omega(int b, const Vec3& w) const;
  double kinetic_translational(int b) const { return 0.5 * mass[b] * vcm[b].squaredNorm(); }
  double kinetic_rotational(int b) const { return 0.5 * omega[b].dot(angmom[b]); }

  /// Doubles of one body's dynamic state: xcm, vcm, angmom, omega, fcm, torque
  /// (3 each), quat (w, x, y, z).
  static constexpr int kStateSize = 22;
  /// Write body b's dynamic state to s[0 .. kStateSize).
  void pack_state(int b, double* s) const;
  /// Set body b's dynamic state from s[0 .. kStateSize) and mark it current.
  void unpack_state(int b, const double* s);

  /// Binary image of every body (restart files) and its inverse.
  void pack(std::string& out) const;
  /// Throws std::runtime_error on a malformed image.
  void unpack(const std::string& in);

 private:
  void rebuild_index();
  /// Mass shares of one body's sub-spheres (see mass_share).
  static std::vector<double> mass_shares(const std::vector<Vec3>& body_offsets,
                                         const std::vector<double>& body_radii);
  int find_sorted(tagint id) const;
  bool dense_ = true;       // ids are compact enough for a direct table
  std::vector<int> index_;  // body id -> index (dense_)
};

}  // namespace granary
