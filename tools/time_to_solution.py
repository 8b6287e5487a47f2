#!/usr/bin/python3
"""Time to solution of the silo study at the paper's full size, from measured figures.

Usage: /usr/bin/python3 tools/time_to_solution.py [--results examples/silo_study/results] [--avalanches 100]
       [--granary-rate 1.765e7] [--liggghts-rate 5.03e6]

The paper's DEM silo: 65 x 30 x 10 dc (height x width x depth, dc = 3.2 mm),
filled to 65 dc, discharged avalanche after avalanche down to 40 dc, then
refilled; cylinders as clumps of 50 spheres. For every case of the silo study
with at least one complete cycle in `results`, this prints (Markdown) the
simulated time, steps and particle-steps that 100 non-empty avalanches take
at that size, and the hours Granary and LIGGGHTS need for them on 1, 16 and 64
cores. Where each number comes from:

* bodies at the fill height: solid fraction PHI_T (0.51; the paper's box
  fraction lies between 0.509, cylinders only, and 0.59, spheres only, and
  rises slowly at phi <= 0.1) of the silo volume up to 65 dc, split into
  cylinders and spheres by the case's sphere volume fraction phi;
  sub-spheres: 50 per cylinder plus the spheres; on average over a cycle
  (65 -> 40 dc) 52.5 / 65 of that.
* discharge per cycle: the bodies between 65 and 40 dc (the flat-bottomed
  silo keeps stagnant heaps beside the slit, so this overestimates it).
* simulated time per discharged kilogram and the mean avalanche size: the
  study's campaign at its reduced scale (complete cycles of `results`: from
  the first avalanche's start to the last one's end, with the clog waits and
  arch removals, plus 0.2 s of settling per refill; the refill's fall is
  left out),
  scaled by the slit length, 10 dc here against 6 dc there (flow rate and
  avalanche size taken proportional to it: an assumption).
* timestep: 0.2 of the Rayleigh time of the smallest sphere (the campaign's
  rule): the 50-sphere clump's 0.66 mm spheres, or the glass spheres if smaller.
* speed: particle-steps per second per core measured on the 50-sphere clump
  silo, both programs in one run on 2026-11-28 (doc/performance.md "Time to
  solution", 1 rank, the faster of two: Granary 1.765e7, LIGGGHTS 5.03e6; on
  2026-11-26 the same benchmark gave 1.668e7 and 7.714e6: LIGGGHTS' rate
  varies most between days on this virtual machine; --granary-rate and
  --liggghts-rate set others); 16
  cores: the parallel efficiency measured at 16 ranks on the 198,000-particle
  silo on 2026-11-28 (doc/performance.md "Strong scaling to 16 ranks, the
  build of 2026-11-28": Granary 0.52 with rcb and weight time balancing, 0.47
  without; LIGGGHTS 0.49, which cannot balance); 64 cores:
  the same efficiency (an assumption: about 12,000-15,000 particles per rank
  in both; not measured).
"""
import argparse
import csv
import math
import os
import re
import sys

DC = 3.2e-3
H_FILL, H_STOP, WIDTH, DEPTH = 65.0, 40.0, 30.0, 10.0  # dc
CAMPAIGN_DEPTH = 6.0  # dc: the campaign's slit length
PHI_T = 0.51
RHO_C, RHO_S = 1190.0, 2500.0
V_CYL = 15.0860e-9  # m^3: the 50-sphere clump's volume (potentials/cylinder_ellipse_50.clump)
R_SUB = 0.66e-3  # m: its spheres
YOUNG, NU = 5.0e6, 0.45
DT_FRAC = 0.2
SETTLE = 0.2  # s of settling after each refill (examples/silo_study/in.cycle)
RATE = {"granary": 1.765e7, "liggghts": 5.03e6}  # particle-steps/s on one core (defaults)
EFF = {"granary": 0.52, "liggghts": 0.49}  # parallel efficiency at 16 (and assumed at 64) cores


def rayleigh_time(radius, rho):
    g = YOUNG / (2 * (1 + NU))
    return math.pi * radius * math.sqrt(rho / g) / (0.1631 * NU + 0.8766)


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def campaign(case_dir):
    """(seconds of simulated time per kg discharged, mean non-empty avalanche size in bodies,
    mean mass per body) over the complete cycles, or None."""
    cyc = [c for c in rows(os.path.join(case_dir, "cycles.csv")) if c.get("finished") == "1"]
    if not cyc:
        return None
    done = {c["cycle"] for c in cyc}
    av = [a for a in rows(os.path.join(case_dir, "avalanches.csv")) if a["cycle"] in done]
    nonempty = [a for a in av if float(a["bodies"]) > 0]
    if not nonempty:
        return None
    mass = sum(float(a["mass"]) for a in av)
    bodies = sum(float(a["bodies"]) for a in av)
    # per cycle: from the first avalanche's start to the last one's end (the
    # flow, the clog waits, the arch removals), plus the settling after the
    # refill (SETTLE; the fall of the refill itself is left out)
    sim_time = 0.0
    for cycle in done:
        mine = [a for a in av if a["cycle"] == cycle]
        if mine:
            sim_time += max(float(a["t_end"]) for a in mine) - min(float(a["t_start"]) for a in mine)
        sim_time += SETTLE
    return sim_time / mass, bodies / len(nonempty), mass / bodies


def estimate(r, phi, s_per_kg, mean_s, m_body, avalanches, rate):
    ds = DC / r if r > 0 else 0.0  # (phi = 0: no spheres, no size ratio)
    solid = PHI_T * H_FILL * WIDTH * DEPTH * DC**3
    n_cyl = solid * (1 - phi) / V_CYL
    n_sph = solid * phi / (math.pi / 6 * ds**3) if phi > 0 else 0.0
    subs = 50 * n_cyl + n_sph
    mean_subs = subs * 0.5 * (H_FILL + H_STOP) / H_FILL
    scale = DEPTH / CAMPAIGN_DEPTH
    cycle_mass = (H_FILL - H_STOP) / H_FILL * solid * ((1 - phi) * RHO_C + phi * RHO_S)
    cycle_bodies = cycle_mass / m_body
    av_per_cycle = cycle_bodies / (mean_s * scale)
    cycles = avalanches / av_per_cycle
    sim_time = cycles * cycle_mass * s_per_kg / scale
    rmin = min(R_SUB, 0.5 * ds) if phi > 0 else R_SUB
    rho_min = RHO_S if phi > 0 and 0.5 * ds < R_SUB else RHO_C
    dt = DT_FRAC * rayleigh_time(rmin, rho_min)
    steps = sim_time / dt
    psteps = steps * mean_subs
    hours = {}
    for prog in ("granary", "liggghts"):
        for cores in (1, 16, 64):
            eff = 1.0 if cores == 1 else EFF[prog]
            hours[prog, cores] = psteps / (rate[prog] * cores * eff) / 3600.0
    return dict(subs=subs, cycles=cycles, sim_time=sim_time, dt=dt, steps=steps, psteps=psteps, hours=hours)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default=os.path.join(os.path.dirname(__file__), "..", "examples", "silo_study",
                                                      "results"))
    ap.add_argument("--avalanches", type=int, default=100, help="non-empty avalanches per case (default 100)")
    ap.add_argument("--granary-rate", type=float, default=RATE["granary"],
                    help="Granary's particle-steps/s on one core (default %g)" % RATE["granary"])
    ap.add_argument("--liggghts-rate", type=float, default=RATE["liggghts"],
                    help="LIGGGHTS' particle-steps/s on one core (default %g)" % RATE["liggghts"])
    args = ap.parse_args()
    if args.granary_rate <= 0 or args.liggghts_rate <= 0:
        sys.exit("--granary-rate and --liggghts-rate must be positive")
    rate = {"granary": args.granary_rate, "liggghts": args.liggghts_rate}
    cases, variants = [], []
    for name in sorted(os.listdir(args.results)):
        # the paper's cases only (rR_phiPHI); the study's variants (other clump
        # resolutions, cohesion: a suffix such as _n50 or _coh10000) are left out
        m = re.fullmatch(r"r([0-9.]+)_phi([0-9.]+)", name)
        if m is None:
            if name.startswith("r") and os.path.isdir(os.path.join(args.results, name)):
                variants.append(name)
            continue
        r, phi = float(m.group(1)), float(m.group(2))
        c = campaign(os.path.join(args.results, name))
        if c is None:
            continue
        cases.append((r, phi, name, c))
    if not cases:
        sys.exit("no case with a complete cycle in " + args.results)
    if variants:
        print("(variants left out: %s)" % ", ".join(variants))
    print("| case | sub-spheres at 65 dc | cycles | simulated s | dt (us) | steps | particle-steps | "
          "Granary h, 1 / 16 / 64 cores | LIGGGHTS h, 1 / 16 / 64 cores |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r, phi, name, (s_per_kg, mean_s, m_body) in sorted(cases):
        e = estimate(r, phi, s_per_kg, mean_s, m_body, args.avalanches, rate)
        h = e["hours"]
        print("| %s | %.0f | %.1f | %.0f | %.1f | %.2e | %.2e | %.0f / %.1f / %.1f | %.0f / %.1f / %.1f |" % (
            name, e["subs"], e["cycles"], e["sim_time"], e["dt"] * 1e6, e["steps"], e["psteps"],
            h["granary", 1], h["granary", 16], h["granary", 64], h["liggghts", 1], h["liggghts", 16],
            h["liggghts", 64]))


if __name__ == "__main__":
    main()
