// fix ID group mesh/surface/stress file F.stl type T [mesh/surface keywords]
//     [stress on] [wear off|finnie] [reference_point RX RY RZ]
// (LIGGGHTS syntax): a fix mesh/surface whose forces are reported. The wall
// fixes sum the force of the particles on every triangle each step (for every
// mesh); this style adds the global outputs f_ID[1..9]: the total force on the
// mesh (3), the torque about the reference point (3, each triangle's force
// taken at its centroid) and the reference point itself (3, moved, scaled and
// rotated with the mesh). The per-triangle normal and shear stresses are
// written by dump mesh/vtk. `wear finnie` accumulates Finnie's erosive wear
// per triangle (fix wall/gran adds it, see add_finnie_wear; dump mesh/vtk
// writes it).
// See doc/fixes/mesh_surface_stress.md.
//
// fix ID group mesh/surface/stress/servo file F.stl type T [mesh/surface keywords]
//     com CX CY CZ ctrlPV force|torque axis AX AY AZ target_val V vel_max VM [kp KP] [ki KI] [kd KD]
// (LIGGGHTS' servo mesh module): the mesh is a wall moved along (force) or
// rotated about (torque) the axis through com by a PID controller until the
// force (torque) the wall exerts on the particles along the axis equals
// target_val. See doc/fixes/mesh_surface_stress_servo.md.
#include <mpi.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/utils.h"
#include "fix/fix_mesh_surface.h"
#include "neighbor/neighbor.h"

namespace granary {

namespace {

class FixMeshSurfaceStress : public FixMeshSurface {
 public:
  FixMeshSurfaceStress(Engine& engine, const Args& args) : FixMeshSurface(engine, args, true) {
    size_vector = 9;
  }

  double compute_vector(int i) override {
    if (i < 0 || i >= 9) return 0.0;
    if (i >= 6) return reference_point_[i - 6];
    const std::int64_t step = engine_.update->ntimestep;
    if (step != summed_step_) {
      // sum over the triangles of this rank, then over the ranks
      double local[6] = {0, 0, 0, 0, 0, 0};
      // (the moment about the origin, each force at its contact point, less
      // that of the total force at the reference point)
      for (int t = 0; t < mesh.ntri(); ++t) {
        const Vec3& f = mesh.tri_force[t];
        const Vec3& m = mesh.tri_moment[t];
        for (int d = 0; d < 3; ++d) {
          local[d] += f[d];
          local[3 + d] += m[d];
        }
      }
      MPI_Allreduce(local, sums_, 6, MPI_DOUBLE, MPI_SUM, engine_.world);
      const Vec3 shift = reference_point_.cross(Vec3(sums_[0], sums_[1], sums_[2]));
      for (int d = 0; d < 3; ++d)
        sums_[3 + d] -= shift[d];
      summed_step_ = step;
    }
    return sums_[i];
  }

  void init() override {
    FixMeshSurface::init();
    mesh.tri_moment.assign(mesh.ntri(), Vec3::Zero());
    summed_step_ = -1;
  }

 private:
  std::int64_t summed_step_ = -1;
  double sums_[6] = {0, 0, 0, 0, 0, 0};
};

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The servo keywords and how many values each takes.
int servo_values(const std::string& key) {
  if (key == "com" || key == "axis") return 3;
  if (key == "ctrlPV" || key == "target_val" || key == "vel_max" || key == "kp" || key == "ki" ||
      key == "kd" || key == "mode" || key == "ratio" || key == "dim")
    return 1;
  return -1;
}

// The arguments without the servo keywords (for the mesh/surface/stress
// part); an error when a servo keyword lacks values.
Args without_servo_keywords(const Args& args) {
  Args out;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const int n = k >= 5 ? servo_values(args[k]) : -1;
    if (n < 0) {
      out.push_back(args[k]);
      continue;
    }
    for (int j = 1; j <= n; ++j)
      if (k + j >= args.size() || servo_values(args[k + j]) >= 0)
        throw InputError("fix " + args[0] + " mesh/surface/stress/servo: '" + args[k] + "' needs " +
                         std::to_string(n) + " value(s)");
    k += static_cast<std::size_t>(n);
  }
  return out;
}

class FixMeshSurfaceServo : public FixMeshSurfaceStress {
 public:
  FixMeshSurfaceServo(Engine& engine, const Args& args)
      : FixMeshSurfaceStress(engine, without_servo_keywords(args)) {
    const std::string where = "fix " + id + " mesh/surface/stress/servo";
    const std::string usage =
        "fix ID group mesh/surface/stress/servo file F.stl type T [mesh keywords] com CX CY CZ ctrlPV "
        "force|torque axis AX AY AZ target_val V vel_max VM [kp KP] [ki KI] [kd KD]";
    bool have_com = false, have_ctrl = false, have_axis = false, have_target = false, have_vmax = false;
    for (std::size_t k = 5; k < args.size(); ++k) {
      const std::string& key = args[k];
      const int n = servo_values(key);
      if (n < 0) continue;
      if (k + static_cast<std::size_t>(n) >= args.size())
        throw InputError(where + ": '" + key + "' needs " + std::to_string(n) + " value(s); usage: " + usage);
      const auto num = [&](std::size_t j) {
        if (args[j].rfind("v_", 0) == 0)
          throw InputError(where + ": '" + key + " " + args[j] +
                           "': a variable is not supported here; give a number");
        return parse_double(args[j], where + " " + key);
      };
      if (key == "com") {
        for (int d = 0; d < 3; ++d)
          com_[d] = num(k + 1 + d);
        have_com = true;
      } else if (key == "axis") {
        for (int d = 0; d < 3; ++d)
          axis_[d] = num(k + 1 + d);
        if (!(axis_.norm() > 0.0) || !axis_.allFinite())
          throw InputError(where + ": the axis must be a non-zero vector");
        axis_.normalize();
        have_axis = true;
      } else if (key == "ctrlPV") {
        if (args[k + 1] == "torque")
          torque_ = true;
        else if (args[k + 1] != "force")
          throw InputError(where + ": ctrlPV must be 'force' or 'torque', got '" + args[k + 1] + "'");
        have_ctrl = true;
      } else if (key == "target_val") {
        target_ = num(k + 1);
        if (!(target_ != 0.0) || !std::isfinite(target_))
          throw InputError(where +
                           ": target_val must be a non-zero number (its sign sets the direction "
                           "along the axis)");
        have_target = true;
      } else if (key == "vel_max") {
        vel_max_ = num(k + 1);
        if (!(vel_max_ > 0.0) || !std::isfinite(vel_max_))
          throw InputError(where + ": vel_max must be a positive number");
        have_vmax = true;
      } else if (key == "kp" || key == "ki" || key == "kd") {
        const double v = num(k + 1);
        if (!(v >= 0.0) || !std::isfinite(v)) throw InputError(where + ": " + key + " must be a number >= 0");
        (key == "kp" ? kp_ : key == "ki" ? ki_ : kd_) = v;
      } else if (key == "mode" || key == "ratio") {
        throw InputError(
            where + ": '" + key +
            "' (the gain-scheduled controller of mode auto) is not supported; Granary's servo is "
            "the PID controller (kp, ki, kd)");
      } else {  // dim
        throw InputError(where +
                         ": 'dim' is not a keyword of this servo; give the direction with 'axis AX AY AZ'");
      }
      k += static_cast<std::size_t>(n);
    }
    for (std::size_t k = 5; k < args.size(); ++k)
      if (args[k] == "reference_point")
        throw InputError(where + ": the torque is taken about com; drop 'reference_point'");
    const char* missing = !have_com      ? "com CX CY CZ"
                          : !have_ctrl   ? "ctrlPV force|torque"
                          : !have_axis   ? "axis AX AY AZ"
                          : !have_target ? "target_val V"
                          : !have_vmax   ? "vel_max VM"
                                         : nullptr;
    if (missing) throw InputError(where + ": missing '" + std::string(missing) + "'; usage: " + usage);
    reference_point_ = com_;
    reset_reference();
    size_vector = 9;
    servo_wall = true;
  }

  unsigned hooks() const override { return PRE_FORCE | INITIAL_INTEGRATE | END_OF_STEP; }

  void init() override {
    FixMeshSurfaceStress::init();
    const std::string where = "fix " + id + " mesh/surface/stress/servo";
    // the fastest node must not cross half the skin in a step (LIGGGHTS'
    // condition); torque: vel_max is the speed of the node farthest from the axis
    reach_ = 1.0;
    if (torque_) {
      reach_ = 0.0;
      for (int k = 0; k < mesh.nnodes(); ++k) {
        const Vec3 r = mesh.node(k) - com_;
        reach_ = std::max(reach_, (r - r.dot(axis_) * axis_).norm());
      }
      if (!(reach_ > 0.0))
        throw InputError(where + ": every node of the mesh lies on the axis; nothing to turn");
    }
    const double dt = engine_.update->dt, skin = engine_.neighbor->skin;
    if (vel_max_ * dt >= 0.5 * skin)
      throw InputError(where + ": vel_max " + number(vel_max_) + " m/s moves the wall " +
                       number(vel_max_ * dt) + " m in a step, not less than half the neighbour skin (" +
                       number(0.5 * skin) + " m); lower vel_max or the timestep, or raise the skin");
    set_motion();
  }

  void initial_integrate() override {
    if (rate_ == 0.0) return;
    const double dt = engine_.update->dt;
    travel_ += rate_ * dt;
    if (torque_) {
      const Eigen::Matrix3d r = Eigen::AngleAxisd(travel_, axis_).toRotationMatrix();
      std::vector<Vec3> nodes(reference_.size());
      for (std::size_t k = 0; k < nodes.size(); ++k)
        nodes[k] = com_ + r * (reference_[k] - com_);
      mesh.set_nodes(nodes);
    } else {
      mesh.place(reference_, axis_ * travel_);
      reference_point_ = com_ + axis_ * travel_;
    }
    set_motion();
  }

  // After the step's forces: the controller sets the rate of the next steps.
  void end_of_step() override {
    if (!integrate_) return;  // fix_modify servo/integrate stop: the wall stands
    const double dt = engine_.update->dt;
    const double pv = process_value();
    const double e = (target_ - pv) / std::abs(target_);
    const double change = started_ ? (e - e_prev_) / dt : 0.0;
    const double sum = e_sum_ + e * dt;
    double out = kp_ * e + ki_ * sum + kd_ * change;
    if (std::abs(out) <= 1.0) {
      e_sum_ = sum;
    } else {  // saturated: the integral does not grow (anti-windup)
      out = out > 0.0 ? 1.0 : -1.0;
    }
    e_prev_ = e;
    started_ = true;
    rate_ = torque_ ? vel_max_ * out / reach_ : vel_max_ * out;
  }

  double compute_vector(int i) override {
    if (i >= 6 && i < 9) return reference_point_[i - 6];
    return FixMeshSurfaceStress::compute_vector(i);
  }

  // fix_modify ID servo/integrate start|stop | servo/target_val V |
  // servo/vel_max V | servo/ctrlParam KP KI KD
  std::size_t modify_param(const Args& a, std::size_t k) override {
    const std::string& w = a[k];
    const std::string where = "fix_modify " + id + " " + w;
    auto need = [&](std::size_t n) {
      if (k + n >= a.size()) throw InputError(where + " needs " + std::to_string(n) + " value(s)");
    };
    if (w == "servo/integrate") {
      need(1);
      if (a[k + 1] != "start" && a[k + 1] != "stop") throw InputError(where + ": expected start or stop");
      integrate_ = a[k + 1] == "start";
      if (!integrate_) rate_ = 0.0;
      set_motion();
      return 2;
    }
    if (w == "servo/target_val") {
      need(1);
      const double v = parse_double(a[k + 1], where);
      if (!(v != 0.0) || !std::isfinite(v)) throw InputError(where + " must be a non-zero number");
      target_ = v;
      return 2;
    }
    if (w == "servo/vel_max") {
      need(1);
      const double v = parse_double(a[k + 1], where);
      if (!(v > 0.0) || !std::isfinite(v)) throw InputError(where + " must be a positive number");
      vel_max_ = v;  // checked against the skin at the next run's start
      return 2;
    }
    if (w == "servo/ctrlParam") {
      need(3);
      double g[3];
      for (int j = 0; j < 3; ++j) {
        g[j] = parse_double(a[k + 1 + j], where);
        if (!(g[j] >= 0.0) || !std::isfinite(g[j]))
          throw InputError(where + ": the gains must be numbers >= 0");
      }
      kp_ = g[0];
      ki_ = g[1];
      kd_ = g[2];
      return 4;
    }
    return 0;
  }

  void pack_restart(std::string& out) const override {
    FixMeshSurfaceStress::pack_restart(out);
    const Vec3 c = current_com();
    const double state[kState] = {kMagic, c[0], c[1], c[2], rate_, e_sum_, e_prev_, started_ ? 1.0 : 0.0};
    out.append(reinterpret_cast<const char*>(state), sizeof state);
  }

  void unpack_restart(const std::string& in) override {
    double state[kState] = {0, 0, 0, 0, 0, 0, 0, 0};
    const std::size_t n = sizeof state;
    if (in.size() > n) std::memcpy(state, in.data() + in.size() - n, n);
    const bool has_servo = in.size() > n && state[0] == kMagic;
    FixMeshSurfaceStress::unpack_restart(has_servo ? in.substr(0, in.size() - n) : in);
    if (has_servo) {
      com_ = Vec3(state[1], state[2], state[3]);
      rate_ = state[4];
      e_sum_ = state[5];
      e_prev_ = state[6];
      started_ = state[7] != 0.0;
    }
    reference_point_ = com_;
    reset_reference();
  }

 private:
  static constexpr int kState = 8;
  static constexpr double kMagic = 7.3619e11;  // marks the servo's state after the mesh's

  // The force (torque about com) the wall exerts on the particles, along the axis.
  double process_value() {
    double local = 0.0;
    const Vec3 c = current_com();
    for (int t = 0; t < mesh.ntri(); ++t) {
      const Vec3& f = mesh.tri_force[t];
      local += torque_ ? (mesh.tri_moment[t] - c.cross(f)).dot(axis_) : f.dot(axis_);
    }
    double total = 0.0;
    MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return -total;
  }

  Vec3 current_com() const { return torque_ ? com_ : Vec3(com_ + axis_ * travel_); }

  // The present nodes and com become the reference of the motion.
  void reset_reference() {
    com_ = current_com();
    travel_ = 0.0;
    reference_.resize(mesh.nnodes());
    for (int k = 0; k < mesh.nnodes(); ++k)
      reference_[k] = mesh.node(k);
  }

  void set_motion() {
    mesh.velocity = torque_ ? Vec3::Zero() : Vec3(axis_ * rate_);
    mesh.omega = torque_ ? Vec3(axis_ * rate_) : Vec3::Zero();
    mesh.origin = com_;
  }

  Vec3 com_ = Vec3::Zero(), axis_ = Vec3::UnitZ();
  bool torque_ = false;
  double target_ = 0.0, vel_max_ = 0.0, kp_ = 1e-2, ki_ = 0.0, kd_ = 0.0;
  double reach_ = 1.0;   // torque: the largest distance of a node from the axis [m]
  double rate_ = 0.0;    // present velocity [m/s] or angular velocity [rad/s] along the axis
  double travel_ = 0.0;  // distance [m] or angle [rad] since the reference
  double e_sum_ = 0.0, e_prev_ = 0.0;
  bool started_ = false;
  bool integrate_ = true;        // fix_modify servo/integrate
  std::vector<Vec3> reference_;  // node positions at travel 0
};

}  // namespace

GRANARY_FIX_STYLE("mesh/surface/stress", FixMeshSurfaceStress);
GRANARY_FIX_STYLE("mesh/surface/stress/servo", FixMeshSurfaceServo);

}  // namespace granary
