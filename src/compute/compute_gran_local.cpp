#include "compute/compute_gran_local.h"

#include "core/error.h"

namespace granary {

namespace {
const char* const kKeywords =
    "pos, vel, id, force, force_normal, force_tangential, torque, history, contactArea, delta, contactPoint";
}  // namespace

ComputeGranLocal::ComputeGranLocal(Engine& engine, const Args& args) : Compute(engine, args) {
  local_flag = true;
  const std::string where = "compute " + id + " " + style;
  if (args.size() == 3) {
    // LIGGGHTS' default: everything but force_normal, force_tangential, delta
    // and contactPoint
    want_pos_ = want_vel_ = want_id_ = want_force_ = want_torque_ = want_history_ = want_area_ = true;
  }
  for (std::size_t k = 3; k < args.size(); ++k) {
    const std::string& w = args[k];
    if (w == "pos")
      want_pos_ = true;
    else if (w == "vel")
      want_vel_ = true;
    else if (w == "id")
      want_id_ = true;
    else if (w == "force")
      want_force_ = true;
    else if (w == "force_normal")
      want_fn_ = true;
    else if (w == "force_tangential")
      want_ft_ = true;
    else if (w == "torque")
      want_torque_ = true;
    else if (w == "history")
      want_history_ = true;
    else if (w == "contactArea")
      want_area_ = true;
    else if (w == "delta")
      want_delta_ = true;
    else if (w == "contactPoint")
      want_point_ = true;
    else if (w == "heatFlux")
      throw InputError(
          where +
          ": heatFlux needs the conductive heat transfer of fix heat/gran, which Granary does not "
          "have; remove the keyword");
    else if (w == "ms_id")
      throw InputError(where +
                       ": ms_id is not supported; the clump of each particle is the per-atom value 'body' "
                       "(dump custom ... body)");
    else
      throw InputError(where + ": unknown keyword '" + w + "'; expected any of " + kKeywords);
  }
}

ComputeGranLocal::Layout ComputeGranLocal::layout() const {
  Layout L;
  auto take = [&L](bool want, int& first, int n) {
    if (!want) return;
    first = L.ncols;
    L.ncols += n;
  };
  L.wall = wall();
  L.nhistory = history_size();
  take(want_pos_, L.pos, 6);
  take(want_vel_, L.vel, 6);
  take(want_id_, L.id, 3);
  take(want_force_, L.force, 3);
  take(want_fn_, L.force_normal, 3);
  take(want_ft_, L.force_tangential, 3);
  take(want_torque_, L.torque, 3);
  take(want_history_, L.history, L.nhistory);
  take(want_area_, L.contact_area, 1);
  take(want_delta_, L.delta, 1);
  take(want_point_, L.contact_point, 3);
  return L;
}

}  // namespace granary
