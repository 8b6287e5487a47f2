#include "particles/bodies.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace granary {

namespace {

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
void put_vec(std::string& out, const Vec3& v) {
  for (int d = 0; d < 3; ++d)
    put<double>(out, v[d]);
}

class Cursor {
 public:
  explicit Cursor(const std::string& s) : s_(s) {}
  template <class T>
  T get() {
    if (pos_ + sizeof(T) > s_.size()) throw std::runtime_error("multisphere body data ends early");
    T v;
    std::memcpy(&v, s_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  Vec3 vec() {
    Vec3 v;
    for (int d = 0; d < 3; ++d)
      v[d] = get<double>();
    return v;
  }
  bool done() const { return pos_ == s_.size(); }

 private:
  const std::string& s_;
  std::size_t pos_ = 0;
};

constexpr std::uint32_t kFormat = 1;

/// Drop the entries whose `doomed` flag is set, keeping the order of the rest.
template <class T>
void erase_marked(std::vector<T>& a, const std::vector<char>& doomed) {
  std::size_t w = 0;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!doomed[r]) a[w++] = a[r];
  a.resize(w);
}

}  // namespace

int Bodies::add(tagint id, tagint first, int atom_type, double m, double vol, double rho, const Vec3& moments,
                const std::vector<Vec3>& body_offsets, const std::vector<double>& body_radii, const Vec3& x,
                const Eigen::Quaterniond& q, const Vec3& v, const Vec3& w) {
  if (id < 0) throw std::invalid_argument("body ids must not be negative");
  if (find(id) >= 0) throw std::invalid_argument("body id " + std::to_string(id) + " is already used");
  if (body_offsets.empty() || body_offsets.size() != body_radii.size()) {
    throw std::invalid_argument("a body needs one radius per sub-sphere and at least one sub-sphere");
  }
  if (!(m > 0.0)) throw std::invalid_argument("a body needs a positive mass");
  if (sphere_start.empty()) sphere_start.push_back(0);
  // position in id order (appending is the usual case)
  const int b = static_cast<int>(std::lower_bound(tag.begin(), tag.end(), id) - tag.begin());
  const int ns = static_cast<int>(body_offsets.size());
  const int at = sphere_start[b];
  // Sub-sphere mass shares; the body origin moves to their centre, which is
  // the centre of mass up to the integration error (or exactly, when the
  // shares could be adjusted), leaving the sphere positions unchanged.
  const std::vector<double> shares = mass_shares(body_offsets, body_radii);
  Vec3 shift = Vec3::Zero();
  for (int k = 0; k < ns; ++k)
    shift += shares[k] * body_offsets[k];
  tag.insert(tag.begin() + b, id);
  first_id.insert(first_id.begin() + b, first);
  type.insert(type.begin() + b, atom_type);
  nspheres.insert(nspheres.begin() + b, ns);
  mass.insert(mass.begin() + b, m);
  volume.insert(volume.begin() + b, vol);
  density.insert(density.begin() + b, rho);
  bounding_radius.insert(bounding_radius.begin() + b, 0.0);
  inertia.insert(inertia.begin() + b, moments);
  xcm.insert(xcm.begin() + b, x + q.normalized() * shift);
  vcm.insert(vcm.begin() + b, v);
  quat.insert(quat.begin() + b, q.normalized());
  angmom.insert(angmom.begin() + b, Vec3::Zero());
  omega.insert(omega.begin() + b, Vec3::Zero());
  fcm.insert(fcm.begin() + b, Vec3::Zero());
  torque.insert(torque.begin() + b, Vec3::Zero());
  current.insert(current.begin() + b, 1);
  offsets.insert(offsets.begin() + at, body_offsets.begin(), body_offsets.end());
  for (int k = 0; k < ns; ++k)
    offsets[at + k] -= shift;
  radii.insert(radii.begin() + at, body_radii.begin(), body_radii.end());
  mass_share.insert(mass_share.begin() + at, shares.begin(), shares.end());
  sphere_start.insert(sphere_start.begin() + b + 1, at + ns);
  for (std::size_t k = b + 2; k < sphere_start.size(); ++k)
    sphere_start[k] += ns;
  for (int k = 0; k < ns; ++k)
    bounding_radius[b] = std::max(bounding_radius[b], offsets[at + k].norm() + radii[at + k]);
  angmom[b] = angmom_from_omega(b, w);
  omega[b] = omega_from_angmom(b);
  if (b == size() - 1 && dense_ && id < static_cast<tagint>(8 * size() + 1024)) {
    if (static_cast<tagint>(index_.size()) <= id) index_.resize(static_cast<std::size_t>(id + 1), -1);
    index_[id] = b;
  } else {
    rebuild_index();
  }
  return b;
}

void Bodies::remove(const std::vector<char>& doomed) {
  const int n = size();
  std::vector<char> sphere_doomed(offsets.size(), 0);
  for (int b = 0; b < n; ++b)
    if (doomed[b])
      std::fill(sphere_doomed.begin() + sphere_start[b], sphere_doomed.begin() + sphere_start[b + 1], 1);
  erase_marked(offsets, sphere_doomed);
  erase_marked(radii, sphere_doomed);
  erase_marked(mass_share, sphere_doomed);
  erase_marked(tag, doomed);
  erase_marked(first_id, doomed);
  erase_marked(type, doomed);
  erase_marked(nspheres, doomed);
  erase_marked(mass, doomed);
  erase_marked(volume, doomed);
  erase_marked(density, doomed);
  erase_marked(bounding_radius, doomed);
  erase_marked(inertia, doomed);
  erase_marked(xcm, doomed);
  erase_marked(vcm, doomed);
  erase_marked(angmom, doomed);
  erase_marked(omega, doomed);
  erase_marked(quat, doomed);
  erase_marked(fcm, doomed);
  erase_marked(torque, doomed);
  erase_marked(current, doomed);
  sphere_start.assign(1, 0);
  for (int ns : nspheres)
    sphere_start.push_back(sphere_start.back() + ns);
  rebuild_index();
}

void Bodies::clear() {
  std::vector<char> all(size(), 1);
  remove(all);
}

void Bodies::rebuild_index() {
  const tagint top = max_tag();
  dense_ = top < static_cast<tagint>(8 * size() + 1024);
  index_.clear();
  if (!dense_) return;
  index_.assign(static_cast<std::size_t>(top + 1), -1);
  for (int b = 0; b < size(); ++b)
    index_[tag[b]] = b;
}

int Bodies::find_sorted(tagint id) const {
  auto it = std::lower_bound(tag.begin(), tag.end(), id);
  return (it != tag.end() && *it == id) ? static_cast<int>(it - tag.begin()) : -1;
}

std::vector<double> Bodies::mass_shares(const std::vector<Vec3>& d, const std::vector<double>& r) {
  const std::size_t n = r.size();
  std::vector<double> w0(n), w(n);
  double sum = 0.0;
  for (std::size_t k = 0; k < n; ++k)
    sum += w0[k] = r[k] * r[k] * r[k];
  for (double& x : w0)
    x /= sum;
  // Smallest relative change (sum of (w - w0)^2 / w0) with sum w = 1 and
  // sum w d = 0: w_k = w0_k (1 + a + b.d_k), a = -b.m0, (M2 - m0 m0^T) b = -m0,
  // where m0 = sum w0 d and M2 = sum w0 d d^T.
  Vec3 m0 = Vec3::Zero();
  Eigen::Matrix3d m2 = Eigen::Matrix3d::Zero();
  double scale = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    m0 += w0[k] * d[k];
    m2 += w0[k] * d[k] * d[k].transpose();
    scale = std::max(scale, d[k].norm() + r[k]);
  }
  if (m0.norm() <= 1e-14 * scale) return w0;
  // directions with no spread (all offsets in a plane or on a line) have m0 = 0 there
  const Eigen::Matrix3d c = m2 - m0 * m0.transpose();
  Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix3d> cod(c);
  cod.setThreshold(1e-8);  // no reweighting along directions the offsets do not span
  const Vec3 b = cod.solve(-m0);
  const double a = -b.dot(m0);
  for (std::size_t k = 0; k < n; ++k) {
    w[k] = w0[k] * (1.0 + a + b.dot(d[k]));
    if (!(w[k] > 0.0)) return w0;  // no positive solution this close: keep the volume shares
  }
  return w;
}

void Bodies::pack_state(int b, double* s) const {
  for (const Vec3* g : {&xcm[b], &vcm[b], &angmom[b], &omega[b], &fcm[b], &torque[b]})
    for (int d = 0; d < 3; ++d)
      *s++ = (*g)[d];
  const Eigen::Quaterniond& q = quat[b];
  s[0] = q.w(), s[1] = q.x(), s[2] = q.y(), s[3] = q.z();
}

void Bodies::unpack_state(int b, const double* s) {
  xcm[b] = Vec3(s[0], s[1], s[2]);
  vcm[b] = Vec3(s[3], s[4], s[5]);
  angmom[b] = Vec3(s[6], s[7], s[8]);
  omega[b] = Vec3(s[9], s[10], s[11]);
  fcm[b] = Vec3(s[12], s[13], s[14]);
  torque[b] = Vec3(s[15], s[16], s[17]);
  quat[b] = Eigen::Quaterniond(s[18], s[19], s[20], s[21]);
  current[b] = 1;
}

Vec3 Bodies::omega_from_angmom(int b) const {
  const Eigen::Matrix3d r = rotation(b);
  Vec3 lb = r.transpose() * angmom[b];
  for (int d = 0; d < 3; ++d)
    lb[d] = inertia[b][d] > 0.0 ? lb[d] / inertia[b][d] : 0.0;
  return r * lb;
}

Vec3 Bodies::angmom_from_omega(int b, const Vec3& w) const {
  const Eigen::Matrix3d r = rotation(b);
  const Vec3 wb = r.transpose() * w;
  return r * inertia[b].cwiseProduct(wb);
}

void Bodies::pack(std::string& out) const {
  put<std::uint32_t>(out, kFormat);
  put<std::uint64_t>(out, static_cast<std::uint64_t>(size()));
  for (int b = 0; b < size(); ++b) {
    put<std::int64_t>(out, tag[b]);
    put<std::int64_t>(out, first_id[b]);
    put<std::int32_t>(out, type[b]);
    put<std::int32_t>(out, nspheres[b]);
    put<double>(out, mass[b]);
    put<double>(out, volume[b]);
    put<double>(out, density[b]);
    put_vec(out, inertia[b]);
    put_vec(out, xcm[b]);
    put_vec(out, vcm[b]);
    put_vec(out, angmom[b]);
    put<double>(out, quat[b].w());
    put<double>(out, quat[b].x());
    put<double>(out, quat[b].y());
    put<double>(out, quat[b].z());
    put_vec(out, fcm[b]);
    put_vec(out, torque[b]);
    for (int k = sphere_start[b]; k < sphere_start[b + 1]; ++k) {
      put_vec(out, offsets[k]);
      put<double>(out, radii[k]);
      put<double>(out, mass_share[k]);
    }
  }
}

void Bodies::unpack(const std::string& in) {
  Cursor c(in);
  if (c.get<std::uint32_t>() != kFormat) throw std::runtime_error("unknown multisphere body data format");
  const auto n = c.get<std::uint64_t>();
  clear();
  for (std::uint64_t k = 0; k < n; ++k) {
    const tagint id = c.get<std::int64_t>();
    const tagint first = c.get<std::int64_t>();
    const int t = c.get<std::int32_t>();
    const int ns = c.get<std::int32_t>();
    if (ns < 1 || ns > (1 << 24)) throw std::runtime_error("multisphere body data: bad sub-sphere count");
    const double m = c.get<double>(), vol = c.get<double>(), rho = c.get<double>();
    const Vec3 moments = c.vec(), x = c.vec(), v = c.vec(), l = c.vec();
    const double qw = c.get<double>(), qx = c.get<double>(), qy = c.get<double>(), qz = c.get<double>();
    const Vec3 f = c.vec(), tq = c.vec();
    std::vector<Vec3> off(ns);
    std::vector<double> rad(ns), share(ns);
    for (int s = 0; s < ns; ++s) {
      off[s] = c.vec();
      rad[s] = c.get<double>();
      share[s] = c.get<double>();
    }
    int b;
    try {
      b = add(id, first, t, m, vol, rho, moments, off, rad, x, Eigen::Quaterniond(qw, qx, qy, qz), v,
              Vec3::Zero());
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("multisphere body data: ") + e.what());
    }
    // exact values as stored (no renormalisation), so a restarted run continues bit for bit
    quat[b] = Eigen::Quaterniond(qw, qx, qy, qz);
    xcm[b] = x;
    for (int s = 0; s < ns; ++s) {
      offsets[sphere_start[b] + s] = off[s];
      mass_share[sphere_start[b] + s] = share[s];
    }
    angmom[b] = l;
    omega[b] = omega_from_angmom(b);
    fcm[b] = f;
    torque[b] = tq;
  }
  if (!c.done()) throw std::runtime_error("multisphere body data has trailing bytes");
}

}  // namespace granary
