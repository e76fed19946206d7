#!/usr/bin/env python3
"""Regenerates docs/benchmarks.md and docs/benchmarks-scaling.png (about 10 minutes on 2 cores).

    /usr/bin/python3 bench/run_benchmarks.py [--exe build/grainlab] [--quick] [--no-yade]

1. Throughput, side by side: `grainlab bench triaxial-iso` (2000 spheres of the [W] grading
   compacted to 100 kPa, contact moments) and bench/peer/yade_bench.py on the same packing file,
   the same time step and the same number of steps, on 1 and 2 threads; ratio grainlab / YADE.
2. Scaling: `grainlab bench lattice` from 10^3 to 10^6 spheres (about 1.5 contacts per sphere, as
   in the compacted sample), cost per particle-step and peak RSS per particle.
3. Time to result: `grainlab run preset:w-base` (prep to e0 = 0.60, 100 kPa, shear to 20 % at
   I = 0.98e-3) on 2 threads.

Raw results go to bench/results/latest.json; the machine must otherwise be idle for the numbers
to mean anything. Timings are never pass/fail tests.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def bench(exe, scene, n, steps, threads):
    out = subprocess.run([exe, "bench", scene, "--particles", str(n), "--steps", str(steps),
                          "--threads", str(threads), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def yade_bench(packing, steps, dt, threads, periodic=False):
    yade = shutil.which("yade")
    if not yade:
        return None
    out = subprocess.run([yade, "-n", f"-j{threads}", "-x", os.path.join(ROOT, "bench", "peer", "yade_bench.py"),
                          packing, "--steps", str(steps), "--dt", repr(dt), *(["--periodic"] if periodic else [])],
                         capture_output=True, text=True, timeout=3600)
    for line in reversed(out.stdout.splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    raise RuntimeError("yade_bench.py printed no result:\n" + out.stdout[-2000:] + out.stderr[-2000:])


def liggghts_bench(packing, steps, dt, procs):
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "peer", "liggghts_bench.py"), packing,
                          "--steps", str(steps), "--dt", repr(dt), "--procs", str(procs)],
                         capture_output=True, text=True, timeout=3600)
    if out.returncode != 0:
        raise RuntimeError("liggghts_bench.py failed:\n" + out.stderr[-3000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def yade_version():
    yade = shutil.which("yade")
    if not yade:
        return None
    try:
        out = subprocess.run([yade, "--version"], capture_output=True, text=True, timeout=120)
        m = re.search(r"\d{4}\.\d{2}[a-z]?", out.stdout + out.stderr)
        return m.group(0) if m else "unknown"
    except Exception:  # noqa: BLE001
        return "unknown"


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    gxx = subprocess.run(["g++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    flags = "unknown"
    cache = os.path.join(ROOT, "build", "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache) as f:
            for line in f:
                if line.startswith("CMAKE_CXX_FLAGS_RELEASE:"):
                    flags = line.split("=", 1)[1].strip()
    return {"cpu": model, "cores": os.cpu_count(), "os": platform.platform(), "compiler": gxx,
            "flags": flags + " -fopenmp"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "grainlab"))
    ap.add_argument("--quick", action="store_true", help="fewer steps and no 10^6 case (a smoke run)")
    ap.add_argument("--no-yade", action="store_true")
    ap.add_argument("--no-liggghts", action="store_true")
    ap.add_argument("--no-time-to-result", action="store_true")
    ap.add_argument("--parts", default="throughput,scenes,scaling,time",
                    help="comma-separated subset of throughput, scenes, scaling, time; the other parts are kept "
                         "from bench/results/latest.json")
    opt = ap.parse_args()
    parts = set(opt.parts.split(","))
    latest = os.path.join(ROOT, "bench", "results", "latest.json")
    res = {"date": datetime.date.today().isoformat(), "machine": machine(), "throughput": [], "scaling": []}
    if parts != {"throughput", "scenes", "scaling", "time"} and os.path.exists(latest):
        with open(latest) as f:
            old = json.load(f)
        for key in ("throughput", "concurrent_single_thread", "yade_version", "scenes", "busy", "scaling",
                    "time_to_result"):
            if key in old:
                res[key] = old[key]
    if "throughput" in parts:
        res["throughput"] = []
        throughput(opt, res)
    if "scenes" in parts:
        scenes(opt, res)
    if "scaling" in parts:
        res["scaling"] = []
        scaling(opt, res)
    if "time" in parts and not opt.no_time_to_result:
        time_to_result(opt, res)

    os.makedirs(os.path.dirname(latest), exist_ok=True)
    with open(latest + ".tmp", "w") as f:
        json.dump(res, f, indent=1)
    os.replace(latest + ".tmp", latest)
    write_report(res)
    return 0


def throughput(opt, res):
    # 1. Throughput, grainlab and YADE on the same packing, dt and steps.
    steps = 2000 if opt.quick else 20000
    for threads in (1, 2):
        g = bench(opt.exe, "triaxial-iso", 2000, steps, threads)
        g["program"] = "grainlab"
        res["throughput"].append(g)
        print(json.dumps(g), flush=True)
    # Two independent one-thread runs at the same time: if each keeps its solo speed, the two vCPUs
    # are independent cores and poor thread scaling is grainlab's; if both slow down, they share a
    # core or memory bandwidth and no code change gets 2x on this machine.
    procs = [subprocess.Popen([opt.exe, "bench", "triaxial-iso", "--particles", "2000", "--steps", str(steps),
                               "--threads", "1", "--json"], stdout=subprocess.PIPE, text=True) for _ in range(2)]
    pair = [json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in procs]
    res["concurrent_single_thread"] = pair
    print(json.dumps(pair), flush=True)
    packing = os.path.join(os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "grainlab",
                           "triaxial-iso-2000.txt")
    if not opt.no_yade and shutil.which("yade"):
        res["yade_version"] = yade_version()
        for threads in (1, 2):
            y = yade_bench(packing, steps, res["throughput"][0]["dt"], threads)
            res["throughput"].append(y)
            print(json.dumps(y), flush=True)
    if not opt.no_liggghts and shutil.which("liggghts"):
        for procs in (1, 2):
            r = liggghts_bench(packing, steps, res["throughput"][0]["dt"], procs)
            res["throughput"].append(r)
            print(json.dumps(r), flush=True)



def prepared_packing(exe, preset, folder, extra=()):
    """The prepared sample (packing.txt) of a preset, from a run that stops right after preparation."""
    subprocess.run([exe, "run", preset, "--out", folder, "--quiet", "--threads", "1", "--set", "test.type=\"isotropic\"",
                    "--set", "output.plots=false", "--set", "output.vtk_every_strain=0", *extra], check=True)
    return os.path.join(folder, "packing.txt")


def bench_packing(exe, packing, config, steps, threads=1):
    out = subprocess.run([exe, "bench", "--packing", packing, "--config", config, "--steps", str(steps),
                          "--threads", str(threads), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def scenes(opt, res):
    """New scenes of issue 15: walls against the periodic cell, a dense well-connected cell, ellipsoids against spheres, the shear phase of w-base, and a 2-thread run
    next to a busy process."""
    steps = 500 if opt.quick else 5000
    res["scenes"] = {}
    use_yade = not opt.no_yade and shutil.which("yade")
    with tempfile.TemporaryDirectory() as tmp:
        # 1. Walls against the cell: the same 2000 spheres of the [W] grading prepared without
        # friction at 100 kPa in the wall box and in the periodic cell (each boundary's densest
        # state), timed alternately twice; YADE on the same files. (A wall packing copied into a
        # cell of the box's size is no equilibrium: its loose wall layers meet at the seams and the
        # cell collapses, so each boundary prepares its own sample.)
        dense = prepared_packing(opt.exe, "preset:periodic-triaxial", os.path.join(tmp, "dense"),
                                 ["--set", "sample.n_particles=2000", "--set", "sample.prep_friction_deg=0",
                                  "--set", "sample.e0=0.5"])
        walls = prepared_packing(opt.exe, "preset:w-base", os.path.join(tmp, "walls"),
                                 ["--set", "sample.prep_friction_deg=0", "--set", "sample.e0=0.5"])
        rows = []
        for _ in range(2):
            w = bench_packing(opt.exe, walls, "preset:w-base", steps)
            w["program"], w["boundary"] = "grainlab", "walls"
            c = bench_packing(opt.exe, dense, "preset:periodic-triaxial", steps)
            c["program"], c["boundary"] = "grainlab", "periodic"
            rows += [w, c]
            print(json.dumps([w, c]), flush=True)
        if use_yade:
            for boundary, path in (("walls", walls), ("periodic", dense)):
                y = yade_bench(path, steps, rows[0]["dt"], 1, periodic=boundary == "periodic")
                y["program"], y["boundary"] = "yade", boundary
                rows.append(y)
                print(json.dumps(y), flush=True)
        res["scenes"]["walls_vs_cell"] = rows

        # 2. Dense, well-connected (the cell sample, Z ~ 5) against YADE: the one-thread numbers
        # are those of the cell just measured; two threads are added.
        one = [r for r in res["scenes"]["walls_vs_cell"] if r["boundary"] == "periodic"]
        rows = [next(r for r in one if r["program"] == "grainlab")]
        g = bench_packing(opt.exe, dense, "preset:periodic-triaxial", steps, 2)
        g["program"] = "grainlab"
        rows.append(g)
        print(json.dumps(g), flush=True)
        if use_yade:
            rows.append(next(r for r in one if r["program"] == "yade"))
            y = yade_bench(dense, steps, rows[0]["dt"], 2, periodic=True)
            y["program"] = "yade"
            rows.append(y)
            print(json.dumps(y), flush=True)
        res["scenes"]["dense_cell"] = rows

        # 3. Ellipsoids against spheres of the same volume: the [O] samples, alternated twice.
        spheroids = prepared_packing(opt.exe, "preset:ouadfel-spheroids", os.path.join(tmp, "spheroids"))
        spheres = prepared_packing(opt.exe, "preset:ouadfel-spheroids", os.path.join(tmp, "spheres"),
                                   ["--set", 'sample.shape={ type = "sphere" }'])  # the whole table: elongation is refused for spheres
        rows = []
        for _ in range(2):
            for shape, path in (("spheres", spheres), ("spheroids", spheroids)):
                r = bench_packing(opt.exe, path, "preset:ouadfel-spheroids", max(300, steps // 3))
                r["program"], r["shape"] = "grainlab", shape
                rows.append(r)
                print(json.dumps(r), flush=True)
        res["scenes"]["ellipsoids"] = rows

    # 4. The shear phase of w-base: two runs that differ only in the final axial strain; the
    # difference of their wall times over the difference of their steps is the shear cost per step.
    if not opt.quick:
        shear = []
        for strain in (0.01, 0.03):
            with tempfile.TemporaryDirectory() as tmp:
                subprocess.run([opt.exe, "run", "preset:w-base", "--out", tmp, "--quiet", "--threads", "1",
                                "--set", f"test.final_axial_strain={strain}", "--set", "output.plots=false",
                                "--set", "output.vtk_every_strain=0"], check=True)
                with open(os.path.join(tmp, "summary.json")) as f:
                    s = json.load(f)
                shear.append({k: s.get(k) for k in ("final_axial_strain", "wall_seconds", "steps", "shear_steps",
                                                    "n_particles")})
                print(json.dumps(shear[-1]), flush=True)
        res["scenes"]["shear_phase"] = shear

    # 5. A busy machine: a 2-thread run while one other process keeps a core busy (here: a
    # one-thread bench), against the same run alone on one thread.
    alone = bench(opt.exe, "triaxial-iso", 2000, steps, 1)
    hog = subprocess.Popen([opt.exe, "bench", "triaxial-iso", "--particles", "2000", "--steps", str(20 * steps),
                            "--threads", "1", "--json"], stdout=subprocess.DEVNULL)
    try:
        import time
        time.sleep(2.0)
        busy = {"one_thread": bench(opt.exe, "triaxial-iso", 2000, steps, 1)}
        for policy in ("", "passive"):
            env = dict(os.environ)
            if policy:
                env["OMP_WAIT_POLICY"] = policy
            out = subprocess.run([opt.exe, "bench", "triaxial-iso", "--particles", "2000", "--steps", str(steps),
                                  "--threads", "2", "--json"], check=True, capture_output=True, text=True, env=env)
            busy[policy or "default"] = json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        hog.kill()
        hog.wait()
    res["busy"] = {"alone_one_thread": alone, "two_threads_next_to_busy": busy}
    print(json.dumps(res["busy"]), flush=True)


def scaling(opt, res):
    # 2. Scaling 10^3 .. 10^6 (particle-steps per run ~ 4e7, at least 100 steps).
    sizes = [1000, 10000, 100000] + ([] if opt.quick else [1000000])
    for n in sizes:
        for threads in (1, 2):
            s = max(100, int((2e6 if opt.quick else 4e7) / n))
            r = bench(opt.exe, "lattice", n, s, threads)
            res["scaling"].append(r)
            print(json.dumps(r), flush=True)


def time_to_result(opt, res):
    # 3. Time to result of the [W] base case.
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([opt.exe, "run", "preset:w-base", "--out", tmp, "--threads", "2", "--quiet"], check=True)
        with open(os.path.join(tmp, "summary.json")) as f:
            s = json.load(f)
    res["time_to_result"] = {k: s.get(k) for k in (
        "wall_seconds", "steps", "shear_steps", "e0", "inertial_number_max", "phi_peak_deg", "phi_res_deg",
        "psi_max_deg", "E_MPa", "n_particles", "lateral_stress_max_deviation")}
    print(json.dumps(res["time_to_result"]), flush=True)


def scenes_report(res):
    sc, out = res.get("scenes") or {}, []
    rate = lambda r: r["particle_steps_per_s"]  # noqa: E731
    per_contact = lambda r: r["steps"] * r["n_contacts"] / r["seconds"] if r.get("n_contacts") else float("nan")  # noqa: E731
    if "walls_vs_cell" in sc:
        rows = sc["walls_vs_cell"]
        out += ["", "## Walls against the periodic cell", "",
                "The same 2000 spheres of the [W] grading prepared without friction at 100 kPa in the box of six servo "
                "walls and in the periodic cell (each boundary's densest state: the cell has no loose wall layer, so it "
                "is denser and has more contacts), held at 100 kPa by the walls' or the cell's servo "
                "(`grainlab bench --packing`, one thread, the [W] law; grainlab alternated twice; YADE on the same "
                "files). A wall packing copied into a cell of the box's size is no equilibrium (its loose wall layers "
                "meet at the seams and the cell collapses), so the overhead of the cell is read per contact-step.", "",
                "| program | boundary | contacts | particle-steps/s | contact-steps/s |", "|---|---|---:|---:|---:|"]
        for r in rows:
            out.append(f"| {r['program']} | {r['boundary']} | {r['n_contacts']} | {rate(r) / 1e6:.2f} M | "
                       f"{per_contact(r) / 1e6:.2f} M |")
        g = [r for r in rows if r["program"] == "grainlab"]
        w = [per_contact(r) for r in g if r["boundary"] == "walls"]
        c = [per_contact(r) for r in g if r["boundary"] == "periodic"]
        if w and c:
            overhead = 100 * (sum(w) / len(w) / (sum(c) / len(c)) - 1)
            spread = max(100 * (max(v) / min(v) - 1) for v in (w, c))
            out += ["", f"Cell overhead per contact-step: {overhead:+.1f} % (target ≤ 10 %; repeated runs of one "
                    f"boundary differ by up to {spread:.0f} %"
                    + ("; negative: the cell is cheaper per contact, having no wall pass)." if overhead < 0 else ").")]
    if "dense_cell" in sc:
        rows = sc["dense_cell"]
        out += ["", "## Dense, well-connected packing", "",
                "2000 spheres of the [W] grading prepared without friction in the periodic cell at 100 kPa (the densest "
                "state), the [W] law, held by the cell's servo; YADE on the same file with its periodic cell and "
                "`PeriTriaxController` at the same Δt and steps.", "",
                "| program | threads | contacts | contacts per sphere | particle-steps/s | grainlab vs YADE |",
                "|---|---:|---:|---:|---:|---:|"]
        g = {r["threads"]: r for r in rows if r["program"] == "grainlab"}
        for r in rows:
            ratio = ""
            if r["program"] == "yade" and r["threads"] in g:
                ratio = f"{rate(g[r['threads']]) / rate(r):.1f}×"
            out.append(f"| {r['program']} | {r['threads']} | {r['n_contacts']} | "
                       f"{2 * r['n_contacts'] / r['n_particles']:.2f} | {rate(r) / 1e6:.2f} M | {ratio} |")
        if 1 in g and 2 in g:
            out += ["", f"grainlab, 2 threads vs 1 on this scene: {rate(g[2]) / rate(g[1]):.2f}× (target ≥ 1.8×)."]
    if "ellipsoids" in sc:
        rows = sc["ellipsoids"]
        out += ["", "## Ellipsoids against spheres", "",
                "The [O] samples of `preset:ouadfel-spheroids` after growth (343 prolate spheroids b/a = 0.7) and the same "
                "preparation with spheres of the same volume, periodic cell at 100 kPa, [O]'s law, one thread, "
                "alternated twice. YADE has no ellipsoid contact (a YADE user would take clumps of spheres, whose cost "
                "grows with the number of spheres per grain, or the polyhedra/level-set packages, neither in Debian's build).",
                "", "| shape | contacts | particle-steps/s | contact-steps/s |", "|---|---:|---:|---:|"]
        for r in rows:
            out.append(f"| {r['shape']} | {r['n_contacts']} | {rate(r) / 1e6:.2f} M | {per_contact(r) / 1e6:.2f} M |")
        sp = [per_contact(r) for r in rows if r["shape"] == "spheres"]
        el = [per_contact(r) for r in rows if r["shape"] == "spheroids"]
        spp = [rate(r) for r in rows if r["shape"] == "spheres"]
        elp = [rate(r) for r in rows if r["shape"] == "spheroids"]
        if sp and el:
            out += ["", f"An ellipsoid costs {sum(spp) / len(spp) / (sum(elp) / len(elp)):.1f}× a sphere per particle-step "
                    f"and {sum(sp) / len(sp) / (sum(el) / len(el)):.1f}× per contact-step (same contact density; target ≤ 3×)."]
    if "shear_phase" in sc and len(sc["shear_phase"]) == 2:
        a, b = sc["shear_phase"]
        ds, dt_ = b["steps"] - a["steps"], b["wall_seconds"] - a["wall_seconds"]
        if ds > 0 and dt_ > 0:
            out += ["", "## Shear phase of w-base", "",
                    f"`grainlab run preset:w-base` on one thread to ε1 = {100 * a['final_axial_strain']:.0f} % and to "
                    f"{100 * b['final_axial_strain']:.0f} % ({a['wall_seconds']:.1f} s and {b['wall_seconds']:.1f} s); the difference, "
                    f"{ds} shear steps in {dt_:.1f} s, is {ds * b['n_particles'] / dt_ / 1e6:.2f} M particle-steps/s "
                    "in the shear phase (the contact network thins while shearing with contact moments)."]
    busy = res.get("busy")
    if busy:
        alone = rate(busy["alone_one_thread"])
        nb = busy["two_threads_next_to_busy"]
        out += ["", "## A busy machine", "",
                "`grainlab bench triaxial-iso` while another one-thread bench keeps one of the cores busy, against one "
                "thread alone:", "",
                "| run | particle-steps/s | vs one thread alone |", "|---|---:|---:|",
                f"| 1 thread, alone | {alone / 1e6:.2f} M | 1.00 |"]
        names = {"one_thread": "1 thread, next to the busy process", "default": "2 threads, next to it (OpenMP default wait)",
                 "passive": "2 threads, next to it, OMP_WAIT_POLICY=passive"}
        for k in ("one_thread", "default", "passive"):
            if k in nb:
                out.append(f"| {names[k]} | {rate(nb[k]) / 1e6:.2f} M | {rate(nb[k]) / alone:.2f} |")
        out += ["", "`grainlab run` (and `resume`, and runs from Python) therefore looks at the running tasks before "
                "it starts: with fewer free cores than `solver.threads` it runs on the free cores and says so on "
                "stderr (results do not depend on the thread count; `GRAINLAB_KEEP_THREADS=1` keeps the requested "
                "count). `grainlab bench` times what it is asked for and only warns."]
    return out


def write_report(res):
    m = res["machine"]
    t = {(r["program"], r["threads"]): r for r in res["throughput"]}
    lines = [
        "# Benchmarks",
        "",
        f"Regenerated by `/usr/bin/python3 bench/run_benchmarks.py` on {res['date']} (raw numbers in "
        "`bench/results/latest.json`). Timings are measurements, never pass/fail tests.",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores, {m['os']}; {m['compiler']}; flags `{m['flags']}` "
        "(portable x86-64, no `-march`).",
        "",
        "## Throughput: grainlab vs YADE on the same scene",
        "",
        "Scene `triaxial-iso`: 2000 spheres of the [W] grading (d = 2–8 mm, straight passing curve by mass), "
        "compacted to 100 kPa (preparation friction 5°), Ec = 30 GPa, ks/kn = 0.3, μ = 30°, β = 0.15, η = 1, "
        "ρ = 2600 kg/m³, α = 0.3, six servo walls at 100 kPa; both programs read the same packing file and run "
        "the same number of steps at the same Δt (YADE " + str(res.get("yade_version", "not installed")) +
        ": `CohFrictMat`, `momentRotationLaw`, `always_use_moment_law`, `useIncrementalForm`; its moment cap "
        "η·min(RA,RB)·Fn differs from grainlab's η·(RA+RB)/2·Fn, a difference in physics, not in cost). "
        "Contacts are sphere–sphere contacts at the end of the run.",
        "",
        "LIGGGHTS 3.8 (Debian `liggghts`, `bench/peer/liggghts_bench.py`) runs the same packing, Δt and steps with "
        "its closest law, `hooke/stiffness` + `tangential history` + `rolling_friction epsd2` (one kn for all pairs, "
        "a light dashpot instead of Cundall damping, no twisting moment, fixed walls instead of servos; threads = MPI "
        "processes).",
        "",
        "| program | threads | particles | contacts | steps | seconds | particle-steps/s | grainlab vs it, same threads |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for (prog, threads), r in sorted(t.items()):
        g = t.get(("grainlab", threads))
        ratio = f"{g['particle_steps_per_s'] / r['particle_steps_per_s']:.1f}×" if (g and prog != "grainlab") else ""
        lines.append(f"| {prog} | {threads} | {r['n_particles']} | {r['n_contacts'] if r['n_contacts'] is not None else '—'} | "
                     f"{r['steps']} | {r['seconds']:.2f} | {r['particle_steps_per_s'] / 1e6:.2f} M | {ratio} |")
    g1, g2 = t.get(("grainlab", 1)), t.get(("grainlab", 2))
    if g1 and g2:
        lines += ["", f"grainlab, 2 threads vs 1: {g2['particle_steps_per_s'] / g1['particle_steps_per_s']:.2f}×."]
    pair = res.get("concurrent_single_thread")
    if g1 and pair:
        each = [r["particle_steps_per_s"] / g1["particle_steps_per_s"] for r in pair]
        lines += [f"Two independent one-thread runs at once: each at {100 * min(each):.0f}–{100 * max(each):.0f} % of "
                  "the solo one-thread speed (100 % would mean two independent cores; less means the two vCPUs "
                  "share a core or memory bandwidth, which caps any two-thread speed-up at the sum)."]
    y1 = t.get(("yade", 1))
    if g1 and y1:
        lines += [f"grainlab 1 thread vs YADE 1 thread: {g1['particle_steps_per_s'] / y1['particle_steps_per_s']:.1f}× "
                  "(target: ≥ 10×)."]

    lines += scenes_report(res)
    lines += ["", "## Scaling and memory", "",
              "Scene `lattice`: n³ spheres on a simple cubic lattice (spacing 5 mm, radii 0.05–0.1 % larger than "
              "half the spacing, seeded) between fixed walls: every sphere presses on its six neighbours, so the "
              "contact density (3 contacts per sphere) is the same for every N and every number of steps; same "
              "law as `triaxial-iso`; no preparation, so that 10⁶ spheres fit in a benchmark run.", "",
              "| particles | contacts | threads | steps | ns per particle-step | particle-steps/s | peak RSS | bytes/particle |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in res["scaling"]:
        lines.append(f"| {r['n_particles']} | {r['n_contacts']} | {r['threads']} | {r['steps']} | "
                     f"{1e9 / r['particle_steps_per_s']:.0f} | {r['particle_steps_per_s'] / 1e6:.2f} M | "
                     f"{r['peak_rss_bytes'] / 2**20:.0f} MiB | {r['bytes_per_particle']:.0f} |")
    one = [r for r in res["scaling"] if r["threads"] == 1]
    if len(one) >= 2:
        costs = [1e9 / r["particle_steps_per_s"] for r in one]
        mid = sorted(costs)[len(costs) // 2]
        lines += ["", f"Cost per particle-step on one thread ranges {min(costs):.0f}–{max(costs):.0f} ns "
                  f"({100 * (min(costs) / mid - 1):+.0f} % / {100 * (max(costs) / mid - 1):+.0f} % around the median; "
                  "target ±25 %). Peak RSS is the whole process (executable, libraries, OpenMP runtime included)."]
    lines += ["", "![cost per particle-step vs N](benchmarks-scaling.png)"]

    if "time_to_result" in res:
        r = res["time_to_result"]
        lines += ["", "## Time to result", "",
                  f"`grainlab run preset:w-base` on 2 threads ({r['n_particles']} spheres: e0 search to "
                  f"{r['e0']:.3f}, isotropic 100 kPa, shear to 20 % at the auto rate, {r['steps']} steps of which "
                  f"{r['shear_steps']} shearing): **{r['wall_seconds']:.0f} s** wall (target ≤ 120 s); largest "
                  f"inertial number {r['inertial_number_max']:.2e}; worst lateral-stress deviation "
                  f"{100 * (r.get('lateral_stress_max_deviation') or float('nan')):.1f} %; φp {r['phi_peak_deg']:.1f}°, "
                  f"φres {r['phi_res_deg']:.1f}°, ψmax {r['psi_max_deg']:.1f}°, E {r['E_MPa']:.0f} MPa. "
                  "No density scaling or other acceleration is used."]
    path = os.path.join(ROOT, "docs", "benchmarks.md")
    notes = os.path.join(ROOT, "bench", "NOTES.md")
    if os.path.exists(notes):
        with open(notes) as f:
            lines += ["", f.read().rstrip()]
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(path + ".tmp", path)

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for threads in (1, 2):
        rs = [r for r in res["scaling"] if r["threads"] == threads]
        if rs:
            ax.plot([r["n_particles"] for r in rs], [1e9 / r["particle_steps_per_s"] for r in rs], "o-",
                    label=f"{threads} thread{'s' if threads > 1 else ''}")
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("particles")
    ax.set_ylabel("wall time per particle-step [ns]")
    ax.set_title("grainlab bench lattice (3 contacts per sphere)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(ROOT, "docs", "benchmarks-scaling.png")
    fig.savefig(png + ".tmp.png", dpi=100)
    os.replace(png + ".tmp.png", png)


if __name__ == "__main__":
    sys.exit(main())
