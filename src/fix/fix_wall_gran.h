// fix wall/gran with primitive walls (LIGGGHTS syntax):
//   fix ID group wall/gran model hertz tangential history [rolling_friction cdt]
//       primitive type T xplane|yplane|zplane POS
//   fix ID group wall/gran ... primitive type T zcylinder RADIUS CX CY
// The wall is a material of atom type T (its Young's modulus, Poisson ratio
// and the pair coefficients of T with each particle type apply). Contact
// history is kept per particle per wall and migrates with the particle.
#pragma once

#include "contact/contact_model.h"
#include "core/vec3.h"
#include "fix/fix.h"
#include "pair/materials.h"

namespace granary {

class FixWallGran : public Fix {
 public:
  FixWallGran(Engine& engine, const Args& args);
  unsigned hooks() const override { return POST_FORCE; }
  void init() override;
  void post_force() override;
  void setup() override {}

  /// Signed distance-based contact with the primitive: overlap and unit normal
  /// pointing from the wall to the particle centre. Returns false without contact.
  bool contact(const Vec3& x, double r, double& overlap, Vec3& n) const;

  enum class Shape { XPlane, YPlane, ZPlane, ZCylinder };

 private:
  contact::ModelSpec spec_;
  MaterialTable materials_;
  Shape shape_ = Shape::ZPlane;
  int wall_type_ = 1;
  double pos_ = 0.0;  // plane position
  double cyl_r_ = 0.0, cyl_cx_ = 0.0, cyl_cy_ = 0.0;
  int field_ = -1;  // per-particle history field
  int nhist_ = 0;
};

}  // namespace granary
