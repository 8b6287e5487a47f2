#include "particles/particles.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/growth.h"

namespace granary {

namespace {
constexpr int kImageBits = 10;
constexpr int kImageMask = (1 << kImageBits) - 1;
constexpr int kImageMax = 1 << (kImageBits - 1);
}  // namespace

Particles::Particles() = default;

int Particles::image_pack(int ix, int iy, int iz) {
  return ((iz + kImageMax) & kImageMask) << (2 * kImageBits) | ((iy + kImageMax) & kImageMask) << kImageBits |
         ((ix + kImageMax) & kImageMask);
}

void Particles::image_unpack(int image, int& ix, int& iy, int& iz) {
  ix = (image & kImageMask) - kImageMax;
  iy = ((image >> kImageBits) & kImageMask) - kImageMax;
  iz = ((image >> (2 * kImageBits)) & kImageMask) - kImageMax;
}

double Particles::sphere_mass(double r, double rho) {
  return 4.0 / 3.0 * M_PI * r * r * r * rho;
}

void Particles::resize(int n) {
  const auto m = static_cast<std::size_t>(n);
  grow_keep(id, m);
  grow_keep(type, m);
  grow_keep(mask, m);
  grow_keep(x, m);
  grow_keep(v, m);
  grow_keep(f, m);
  grow_keep(omega, m);
  grow_keep(torque, m);
  grow_keep(radius, m);
  grow_keep(density, m);
  grow_keep(rmass, m);
  grow_keep(body, m);
  grow_keep(image, m);
  for (auto& e : extras)
    grow_keep(e.data, m * e.ncomp);
}

int Particles::add_local(tagint id_, int type_, const Vec3& x_, double radius_, double density_) {
  const int i = nlocal;
  resize(nlocal + 1);
  id[i] = id_;
  type[i] = type_;
  mask[i] = 1;
  x[i] = x_;
  v[i].setZero();
  f[i].setZero();
  omega[i].setZero();
  torque[i].setZero();
  radius[i] = radius_;
  density[i] = density_;
  rmass[i] = sphere_mass(radius_, density_);
  if (sph) {
    radius[i] = 0.0;
    density[i] = 0.0;
    rmass[i] = type_ < static_cast<int>(type_mass.size()) ? type_mass[type_] : 0.0;
  }
  body[i] = -1;
  image[i] = image_pack(0, 0, 0);
  init_extras(i);
  ++nlocal;
  return i;
}

void Particles::set_sph(bool on) {
  if (on && !sph) {
    // density and pressure travel with the particle and are seen on ghosts
    // (the SPH fixes forward them after every change); the density rate is local
    for (const char* name : {"sph_rho", "sph_p"})
      add_field(name, 1, true, true);
    add_field("sph_drho", 1, false, true);
  } else if (!on && sph) {
    for (const char* name : {"sph_rho", "sph_p", "sph_drho"})
      release_field(name);
  }
  sph = on;
}

void Particles::init_extras(int i) {
  for (auto& e : extras) {
    const auto at = e.data.begin() + static_cast<std::size_t>(i) * e.ncomp;
    if (e.init.size() == static_cast<std::size_t>(e.ncomp))
      std::copy(e.init.begin(), e.init.end(), at);
    else
      std::fill_n(at, e.ncomp, 0.0);
  }
}

void Particles::copy(int from, int to) {
  id[to] = id[from];
  type[to] = type[from];
  mask[to] = mask[from];
  x[to] = x[from];
  v[to] = v[from];
  f[to] = f[from];
  omega[to] = omega[from];
  torque[to] = torque[from];
  radius[to] = radius[from];
  density[to] = density[from];
  rmass[to] = rmass[from];
  body[to] = body[from];
  image[to] = image[from];
  for (auto& e : extras) {
    std::copy_n(e.data.begin() + static_cast<std::size_t>(from) * e.ncomp, e.ncomp,
                e.data.begin() + static_cast<std::size_t>(to) * e.ncomp);
  }
}

void Particles::remove_local(int i) {
  clear_ghosts();
  if (i != nlocal - 1) copy(nlocal - 1, i);
  --nlocal;
  resize(nlocal);
}

void Particles::clear_ghosts() {
  nghost = 0;
  resize(nlocal);
}

namespace {
// Rows k of `a` (ncomp values each) become the former rows order[k], in place:
// each cycle of the permutation is rotated through one saved row, so no copy
// of the array is made (the largest per-particle fields take megabytes).
template <class T>
void reorder(T* a, std::size_t ncomp, const std::vector<int>& order, std::vector<char>& done) {
  const std::size_t n = order.size();
  done.assign(n, 0);
  std::vector<T> saved(ncomp);
  for (std::size_t start = 0; start < n; ++start) {
    if (done[start] || static_cast<std::size_t>(order[start]) == start) {
      done[start] = 1;
      continue;
    }
    std::copy_n(a + start * ncomp, ncomp, saved.begin());
    std::size_t k = start;
    for (;;) {
      done[k] = 1;
      const std::size_t from = static_cast<std::size_t>(order[k]);
      if (from == start) {
        std::copy_n(saved.begin(), ncomp, a + k * ncomp);
        break;
      }
      std::copy_n(a + from * ncomp, ncomp, a + k * ncomp);
      k = from;
    }
  }
}
template <class T>
void reorder(std::vector<T>& a, const std::vector<int>& order, std::vector<char>& done) {
  reorder(a.data(), 1, order, done);
}
}  // namespace

void Particles::permute(const std::vector<int>& order) {
  std::vector<char> done;
  reorder(id, order, done);
  reorder(body, order, done);
  reorder(type, order, done);
  reorder(mask, order, done);
  reorder(image, order, done);
  reorder(radius, order, done);
  reorder(density, order, done);
  reorder(rmass, order, done);
  for (auto* a : {&x, &v, &f, &omega, &torque})
    reorder(*a, order, done);
  for (auto& e : extras)
    reorder(e.data.data(), static_cast<std::size_t>(e.ncomp), order, done);
}

// The fields every particle record starts with (migration and ghosts alike):
// id type mask x(3) v(3) omega(3) radius density rmass body = 16 doubles.
void Particles::pack_core(int i, const Vec3& shift, std::vector<double>& buf) const {
  buf.push_back(static_cast<double>(id[i]));
  buf.push_back(type[i]);
  buf.push_back(mask[i]);
  for (int d = 0; d < 3; ++d)
    buf.push_back(x[i][d] + shift[d]);
  for (int d = 0; d < 3; ++d)
    buf.push_back(v[i][d]);
  for (int d = 0; d < 3; ++d)
    buf.push_back(omega[i][d]);
  buf.push_back(radius[i]);
  buf.push_back(density[i]);
  buf.push_back(rmass[i]);
  buf.push_back(static_cast<double>(body[i]));
}

int Particles::unpack_core(int i, const double* buf) {
  int m = 0;
  id[i] = static_cast<tagint>(buf[m++]);
  type[i] = static_cast<int>(buf[m++]);
  mask[i] = static_cast<int>(buf[m++]);
  for (int d = 0; d < 3; ++d)
    x[i][d] = buf[m++];
  for (int d = 0; d < 3; ++d)
    v[i][d] = buf[m++];
  for (int d = 0; d < 3; ++d)
    omega[i][d] = buf[m++];
  radius[i] = buf[m++];
  density[i] = buf[m++];
  rmass[i] = buf[m++];
  body[i] = static_cast<tagint>(buf[m++]);
  f[i].setZero();
  torque[i].setZero();
  return m;
}

// Extra fields with the given flag, appended to / read from a record.
void Particles::pack_extras(int i, bool ExtraField::*flag, std::vector<double>& buf) const {
  for (const auto& e : extras) {
    if (!(e.*flag)) continue;
    const double* src = &e.data[static_cast<std::size_t>(i) * e.ncomp];
    buf.insert(buf.end(), src, src + e.ncomp);
  }
}

int Particles::unpack_extras(int i, bool ExtraField::*flag, const double* buf) {
  int m = 0;
  for (auto& e : extras) {
    double* dst = &e.data[static_cast<std::size_t>(i) * e.ncomp];
    if (e.*flag) {
      std::copy_n(buf + m, e.ncomp, dst);
      m += e.ncomp;
    } else {
      std::fill_n(dst, e.ncomp, 0.0);
    }
  }
  return m;
}

void Particles::pack_exchange(int i, std::vector<double>& buf) const {
  pack_core(i, Vec3::Zero(), buf);
  buf.push_back(image[i]);
  pack_extras(i, &ExtraField::exchange, buf);
}

int Particles::unpack_exchange(const double* buf) {
  // called only while there are no ghosts (exchange runs before borders)
  const int i = nlocal;
  resize(nlocal + 1);
  int m = unpack_core(i, buf);
  image[i] = static_cast<int>(buf[m++]);
  m += unpack_extras(i, &ExtraField::exchange, buf + m);
  ++nlocal;
  return m;
}

void Particles::pack_border(int i, const Vec3& shift, std::vector<double>& buf) const {
  pack_core(i, shift, buf);
  pack_extras(i, &ExtraField::ghost, buf);
}

int Particles::unpack_borders(const double* buf, std::size_t n) {
  std::size_t per = kCoreValues;
  for (const auto& e : extras)
    if (e.ghost) per += static_cast<std::size_t>(e.ncomp);
  if (n % per != 0) {
    throw std::runtime_error("a ghost message of " + std::to_string(n) + " values is not a whole number of " +
                             std::to_string(per) + "-value records (the ranks disagree on the ghost fields)");
  }
  const int count = static_cast<int>(n / per);
  const int first = nlocal + nghost;
  resize(first + count);
  for (int k = 0; k < count; ++k, buf += per) {
    const int i = first + k;
    const int m = unpack_core(i, buf);
    if (m != kCoreValues) throw std::logic_error("Particles::kCoreValues is not what unpack_core reads");
    image[i] = image_pack(0, 0, 0);
    unpack_extras(i, &ExtraField::ghost, buf + m);
  }
  nghost += count;
  return count;
}

void Particles::map_build(tagint max_id) {
  map_.assign(static_cast<std::size_t>(max_id + 1), -1);
  // ghosts first, so owned copies overwrite them
  for (int i = size() - 1; i >= 0; --i)
    map_[id[i]] = i;
}

void Particles::map_clear() {
  map_.clear();
}

tagint Particles::max_local_id() const {
  tagint m = 0;
  for (int i = 0; i < nlocal; ++i)
    m = std::max(m, id[i]);
  return m;
}

int Particles::add_field(const std::string& name, int ncomp, bool ghost, bool exchange) {
  const int existing = find_field(name);
  if (existing >= 0) {
    // e.g. created by read_restart before the style that owns it was defined
    ExtraField& e = extras[existing];
    if (e.ncomp != ncomp) {
      throw std::invalid_argument("per-particle field '" + name + "' has " + std::to_string(e.ncomp) +
                                  " values per particle, not " + std::to_string(ncomp));
    }
    e.ghost = e.ghost || ghost;
    e.exchange = e.exchange || exchange;
    return existing;
  }
  ExtraField e;
  e.name = name;
  e.ncomp = ncomp;
  e.ghost = ghost;
  e.exchange = exchange;
  e.data.assign(static_cast<std::size_t>(size()) * ncomp, 0.0);
  extras.push_back(std::move(e));
  return static_cast<int>(extras.size()) - 1;
}

void Particles::release_field(const std::string& name) {
  const int k = find_field(name);
  if (k < 0) return;
  ExtraField& e = extras[k];
  e.name.clear();
  e.ncomp = 0;
  e.ghost = e.exchange = e.history = e.settable = false;
  e.init.clear();
  std::vector<double>().swap(e.data);
}

int Particles::find_field(const std::string& name) const {
  for (std::size_t k = 0; k < extras.size(); ++k)
    if (extras[k].name == name) return static_cast<int>(k);
  return -1;
}

double Particles::max_radius(MPI_Comm world) const {
  double r = 0.0, rmax = 0.0;
  for (int i = 0; i < nlocal; ++i)
    r = std::max(r, radius[i]);
  MPI_Allreduce(&r, &rmax, 1, MPI_DOUBLE, MPI_MAX, world);
  return rmax;
}

}  // namespace granary
