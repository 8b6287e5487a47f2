#include "core/atom_properties.h"

#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

int image_flag(const Particles& p, int i, int dim) {
  int im[3];
  Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
  return im[dim];
}

// x, y, z of a vector field: three properties from one accessor
template <int D>
double x_of(const Engine& e, int i) {
  return e.particles->x[i][D];
}
template <int D>
double xs_of(const Engine& e, int i) {
  const Domain& d = *e.domain;
  const double len = d.prd[D] > 0 ? d.prd[D] : 1.0;
  return (e.particles->x[i][D] - d.boxlo[D]) / len;
}
template <int D>
double xu_of(const Engine& e, int i) {
  return e.particles->x[i][D] + image_flag(*e.particles, i, D) * e.domain->prd[D];
}
template <int D>
double image_of(const Engine& e, int i) {
  return static_cast<double>(image_flag(*e.particles, i, D));
}
template <int D>
double v_of(const Engine& e, int i) {
  return e.particles->v[i][D];
}
template <int D>
double f_of(const Engine& e, int i) {
  return e.particles->f[i][D];
}
template <int D>
double omega_of(const Engine& e, int i) {
  return e.particles->omega[i][D];
}
template <int D>
double torque_of(const Engine& e, int i) {
  return e.particles->torque[i][D];
}
double body_of(const Engine& e, int i) {
  return static_cast<double>(e.particles->body[i]);
}

// set's writers
template <int D>
void set_x(Engine& e, int i, double v) {
  e.particles->x[i][D] = v;
}
template <int D>
void set_v(Engine& e, int i, double v) {
  e.particles->v[i][D] = v;
}
template <int D>
void set_omega(Engine& e, int i, double v) {
  e.particles->omega[i][D] = v;
}
void set_type(Engine& e, int i, double v) {
  e.particles->type[i] = static_cast<int>(v);
}
// as LIGGGHTS: the mass follows a new size or density; a new mass leaves the density alone
void set_diameter(Engine& e, int i, double v) {
  Particles& p = *e.particles;
  p.radius[i] = 0.5 * v;
  if (p.density[i] > 0.0) p.rmass[i] = Particles::sphere_mass(p.radius[i], p.density[i]);
}
void set_density(Engine& e, int i, double v) {
  Particles& p = *e.particles;
  p.density[i] = v;
  p.rmass[i] = p.radius[i] > 0.0 ? Particles::sphere_mass(p.radius[i], p.density[i]) : p.density[i];
}
void set_mass(Engine& e, int i, double v) {
  e.particles->rmass[i] = v;
}

// atom_style sph: density and pressure (fields sph_rho, sph_p)
double sph_value(const Engine& e, int i, const char* field, const char* name) {
  const Particles& p = *e.particles;
  const int k = p.find_field(field);
  if (k < 0) throw InputError(std::string("per-atom property '") + name + "' needs atom_style sph");
  return p.extras[k].data[i];
}
void set_meso_rho(Engine& e, int i, double v) {
  Particles& p = *e.particles;
  const int k = p.find_field("sph_rho");
  if (k < 0) throw InputError("set meso_rho needs atom_style sph");
  p.extras[k].data[i] = v;
}

}  // namespace

const std::vector<AtomProperty>& atom_properties() {
  static const std::vector<AtomProperty> table = {
      {"id", true, [](const Engine& e, int i) { return static_cast<double>(e.particles->id[i]); }},
      {"type", true, [](const Engine& e, int i) { return static_cast<double>(e.particles->type[i]); },
       set_type, SetCheck::Type},
      {"body", true, body_of},
      {"mol", true, body_of},
      {"id_multisphere", true, body_of},
      {"mass", false, [](const Engine& e, int i) { return e.particles->rmass[i]; }, set_mass,
       SetCheck::Positive},
      {"density", false, [](const Engine& e, int i) { return e.particles->density[i]; }, set_density,
       SetCheck::Positive},
      {"radius", false, [](const Engine& e, int i) { return e.particles->radius[i]; }},
      {"diameter", false, [](const Engine& e, int i) { return 2.0 * e.particles->radius[i]; }, set_diameter,
       SetCheck::Positive},
      {"x", false, x_of<0>, set_x<0>},
      {"y", false, x_of<1>, set_x<1>},
      {"z", false, x_of<2>, set_x<2>},
      {"xs", false, xs_of<0>},
      {"ys", false, xs_of<1>},
      {"zs", false, xs_of<2>},
      {"xu", false, xu_of<0>},
      {"yu", false, xu_of<1>},
      {"zu", false, xu_of<2>},
      {"ix", true, image_of<0>},
      {"iy", true, image_of<1>},
      {"iz", true, image_of<2>},
      {"vx", false, v_of<0>, set_v<0>},
      {"vy", false, v_of<1>, set_v<1>},
      {"vz", false, v_of<2>, set_v<2>},
      {"fx", false, f_of<0>},
      {"fy", false, f_of<1>},
      {"fz", false, f_of<2>},
      {"omegax", false, omega_of<0>, set_omega<0>},
      {"omegay", false, omega_of<1>, set_omega<1>},
      {"omegaz", false, omega_of<2>, set_omega<2>},
      {"tqx", false, torque_of<0>},
      {"tqy", false, torque_of<1>},
      {"tqz", false, torque_of<2>},
      {"proc", true, [](const Engine& e, int) { return static_cast<double>(e.rank); }},
      {"rho", false, [](const Engine& e, int i) { return sph_value(e, i, "sph_rho", "rho"); }},
      {"meso_rho", false, [](const Engine& e, int i) { return sph_value(e, i, "sph_rho", "meso_rho"); },
       set_meso_rho, SetCheck::Positive},
      {"p", false, [](const Engine& e, int i) { return sph_value(e, i, "sph_p", "p"); }},
  };
  return table;
}

const AtomProperty* find_atom_property(const std::string& name) {
  for (const AtomProperty& a : atom_properties())
    if (name == a.name) return &a;
  return nullptr;
}

std::vector<std::string> settable_atom_property_names() {
  std::vector<std::string> names;
  for (const AtomProperty& a : atom_properties())
    if (a.assign) names.push_back(a.name);
  return names;
}

std::vector<std::string> atom_property_names() {
  std::vector<std::string> names;
  for (const AtomProperty& a : atom_properties())
    names.push_back(a.name);
  return names;
}

}  // namespace granary
