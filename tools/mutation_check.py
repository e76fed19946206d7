#!/usr/bin/python3
"""Mutation check: deliberately wrong variants of the physics must each fail at least one unit test.

Copies the source tree (the files git tracks, with their working-tree contents) into a temporary
folder, builds the unit-test binary there once unchanged (every test must pass), then for each
mutation below: applies the textual change to the copy, rebuilds only `unit_tests`, runs it and
records which tests failed; restores the file before the next mutation. A mutation no test catches
"survives": the tool then exits 1. A mutation whose text is no longer in the source (the code was
changed) is reported as "stale" and also makes the tool exit 1, so the table cannot silently rot.

    /usr/bin/python3 tools/mutation_check.py                 # all mutations, table on stdout
    /usr/bin/python3 tools/mutation_check.py --list          # what each mutation does
    /usr/bin/python3 tools/mutation_check.py --only kn-x2 fs-sign --markdown
    options: --jobs N (build jobs, default 2), --timeout S (per test run, default 900), --keep

Cost on the 2-core development machine: about one to two minutes per mutation (a changed header
recompiles most of the core); ccache, when installed, makes restoring a file free. Every child
process gets an argument vector, never a shell.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@dataclass(frozen=True)
class Mutation:
    name: str
    path: str          # relative to the repository root
    old: str           # must occur exactly once in the file
    new: str
    what: str


MUTATIONS = [
    Mutation("fs-sign", "src/contact/slots.hpp",
             "Vec3 trial = carriedShear - ks * dXs;", "Vec3 trial = carriedShear + ks * dXs;",
             "shear force increment with the wrong sign (Fs pushes along the slip)"),
    Mutation("kn-x2", "src/contact/models.hpp",
             "return constantKn > 0.0 ? constantKn : 2.0 * young * rA * rB / (rA + rB);",
             "return constantKn > 0.0 ? constantKn : 4.0 * young * rA * rB / (rA + rB);",
             "particle-particle Kn twice too large"),
    Mutation("ks-ignored", "src/contact/slots.hpp",
             "Vec3 trial = carriedShear - ks * dXs;", "Vec3 trial = carriedShear - 0.0 * ks * dXs;",
             "Ks ignored: the shear spring never loads (Fs = 0)"),
    Mutation("moment-limit-off", "src/contact/models.hpp",
             "momentElasticPlastic(carriedMoment, p.kr, dTheta, p.momentLimitArm * fn)",
             "momentElasticPlastic(carriedMoment, p.kr, dTheta, 1e300)",
             "no plastic limit on the contact moment"),
    Mutation("coulomb-angle", "src/contact/slots.hpp",
             "const double limit = normalForce * tanFriction;",
             "const double limit = normalForce * std::atan(tanFriction);",
             "Coulomb limit with the friction angle (rad) instead of its tangent"),
    Mutation("wall-friction-no-tan", "src/lab/protocols.cpp",
             "w.tanFriction = std::tan(degToRad(c.contact.wallFrictionDeg));",
             "w.tanFriction = degToRad(c.contact.wallFrictionDeg);",
             "wall friction from the config taken as the angle in radians, not tan"),
    Mutation("rolling-linear-twists", "src/contact/models.hpp",
             "combineRollingFriction(combine, muA, muB) * rBar, false};",
             "combineRollingFriction(combine, muA, muB) * rBar, true};",
             "linear rolling resistance also resists twisting"),
    Mutation("damping-sign", "src/core/kernels/damping.hpp",
             "return ((-alpha) * f.array().abs() * v.array().sign()).matrix();",
             "return (alpha * f.array().abs() * v.array().sign()).matrix();",
             "Cundall damping force along the velocity instead of against it"),
    Mutation("leapfrog-old-velocity", "src/core/kernels/integrate.hpp",
             "x[i] += v[i] * h;", "x[i] += vOld * h;",
             "positions advanced with the old velocity (explicit Euler, not leapfrog)"),
    Mutation("torque-a-sign", "src/core/contact_driver.hpp",
             "list.torqueA[c] = g.branchA.cross(-res.force) + res.moment;",
             "list.torqueA[c] = g.branchA.cross(res.force) + res.moment;",
             "torque of the contact force on body A with the wrong sign"),
    Mutation("servo-sign", "src/core/simulation.cpp",
             "const double error = wall.targetStress - sigma;",
             "const double error = sigma - wall.targetStress;",
             "wall servo error with the wrong sign"),
    Mutation("servo-no-integral", "src/core/simulation.cpp",
             "inwardSpeed = servo.gain * u / dt + wall.servoIntegral;",
             "inwardSpeed = servo.gain * u / dt;",
             "wall servo without its integral term"),
    Mutation("dt-no-rotation", "src/core/time_step.cpp",
             "dtc = std::min(dtc, std::sqrt(particles.inertia[i] / model.maxRotationalStiffness(r)));",
             "",
             "critical time step ignores the rotational springs"),
    Mutation("verlet-no-skin", "src/core/broad_phase.cpp",
             "const double reach = r[a] + r[b] + skin;", "const double reach = r[a] + r[b];",
             "Verlet list built without the skin"),
    Mutation("verlet-threshold-skin", "src/core/broad_phase.hpp",
             "double halfSkin() const { return 0.5 * skin; }", "double halfSkin() const { return skin; }",
             "Verlet list rebuilt only after a full skin of motion"),
    Mutation("love-weber-wall-sign", "src/lab/measurements.cpp",
             "if (c.wall) s -= c.force * c.branch.transpose();", "if (c.wall) s += c.force * c.branch.transpose();",
             "Love-Weber stress: wall contacts with the wrong sign"),
    Mutation("grading-uniform-in-interval", "src/lab/grading.cpp",
             "v = 1.0 / std::sqrt(a - s * (a - b));", "v = D[k] + s * (D[k + 1] - D[k]);",
             "sieve curve sampled uniformly by number within each interval (not by mass)"),
    Mutation("ellipsoid-inertia-2-5", "src/geometry/ellipsoid_shape.hpp",
             "return mass / 5.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());",
             "return 2.0 * mass / 5.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());",
             "ellipsoid inertia with [O] eq. 3.19's misprinted 2/5"),
    Mutation("viscous-damping-explicit", "src/core/kernels/damping.hpp",
             "k.momentum = ((1.0 - ha) * momentum + dt * force) / (1.0 + ha);",
             "k.momentum = (1.0 - 2.0 * ha) * momentum + dt * force;",
             "viscous damping integrated explicitly instead of at the midpoint ([O])"),
]


def run(args, cwd, log, timeout=None, env=None):
    """Runs an argument vector; its output goes to the open log file. Returns the exit code."""
    log.write(f"$ {' '.join(args)}\n")
    log.flush()
    try:
        return subprocess.run(args, cwd=cwd, stdout=log, stderr=subprocess.STDOUT, timeout=timeout, env=env).returncode
    except subprocess.TimeoutExpired:
        return None


def copy_tree(dest):
    """Copies the files git tracks (working-tree contents, so uncommitted edits count too)."""
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for rel in listed.decode().split("\0"):
        if not rel:
            continue
        src = os.path.join(ROOT, rel)
        if not os.path.isfile(src):
            continue
        dst = os.path.join(dest, rel)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copy2(src, dst)


def configure(tree, log):
    args = ["cmake", "-S", tree, "-B", os.path.join(tree, "build"), "-DCMAKE_BUILD_TYPE=Release"]
    if shutil.which("ninja"):
        args += ["-G", "Ninja"]
    if shutil.which("ccache"):
        args += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
    return run(args, tree, log)


def build(tree, jobs, log):
    return run(["cmake", "--build", os.path.join(tree, "build"), "--target", "unit_tests", "-j", str(jobs)], tree, log)


def run_tests(tree, timeout, log):
    """Runs the unit tests; returns (status, failed test names). status: ok, failed, timeout, crash."""
    report = os.path.join(tree, "build", "gtest.json")
    if os.path.exists(report):
        os.remove(report)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    binary = os.path.join(tree, "build", "tests", "unit_tests")
    log_start = log.tell()
    code = run([binary, f"--gtest_output=json:{report}"], tree, log, timeout=timeout, env=env)
    failed = []
    if os.path.exists(report):
        with open(report) as f:
            data = json.load(f)
        for suite in data.get("testsuites", []):
            for test in suite.get("testsuite", []):
                if test.get("failures"):
                    failed.append(f"{suite['name']}.{test['name']}")
    if code is None or (code != 0 and not failed):
        # Killed by the timeout or by a signal before the report was written: name the test that
        # was running from the log.
        log.flush()
        with open(log.name) as f:
            f.seek(log_start)
            text = f.read()
        running = [line.split("]", 1)[1].strip() for line in text.splitlines() if line.startswith("[ RUN      ]")]
        done = {line.split("]", 1)[1].split("(")[0].strip() for line in text.splitlines()
                if line.startswith("[       OK ]") or line.startswith("[  FAILED  ]")}
        stuck = [t for t in running if t not in done]
        return ("timeout" if code is None else f"crash (exit {code})"), failed + stuck[:1]
    return ("ok" if code == 0 else "failed"), failed


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run only these mutations")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    parser.add_argument("--jobs", type=int, default=2, help="build jobs (default 2)")
    parser.add_argument("--timeout", type=int, default=900, help="seconds per test run (default 900)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary tree")
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    opt = parser.parse_args()

    if opt.list:
        for m in MUTATIONS:
            print(f"{m.name:28s} {m.path:28s} {m.what}")
        return 0
    names = {m.name for m in MUTATIONS}
    for n in opt.only or []:
        if n not in names:
            print(f"mutation_check: --only {n}: unknown; allowed: {', '.join(sorted(names))}", file=sys.stderr)
            return 2
    chosen = [m for m in MUTATIONS if not opt.only or m.name in opt.only]

    tree = tempfile.mkdtemp(prefix="grainlab-mutation-")
    log = open(os.path.join(tree, "mutation.log"), "w+")
    print(f"mutation_check: tree {tree}, log {log.name}", file=sys.stderr)
    results = []
    try:
        copy_tree(tree)
        if configure(tree, log) != 0 or build(tree, opt.jobs, log) != 0:
            print("mutation_check: the unchanged tree does not build (see the log)", file=sys.stderr)
            return 2
        status, failed = run_tests(tree, opt.timeout, log)
        if status != "ok":
            print(f"mutation_check: the unchanged tree fails its tests: {status} {failed}", file=sys.stderr)
            return 2
        for m in chosen:
            path = os.path.join(tree, m.path)
            with open(path) as f:
                original = f.read()
            if original.count(m.old) != 1:
                results.append((m, "stale", [f"text found {original.count(m.old)} times in {m.path}"], 0.0))
                continue
            start = time.time()
            try:
                with open(path, "w") as f:
                    f.write(original.replace(m.old, m.new))
                if build(tree, opt.jobs, log) != 0:
                    results.append((m, "does not compile", [], time.time() - start))
                    continue
                status, failed = run_tests(tree, opt.timeout, log)
                results.append((m, "caught" if failed or status != "ok" else "SURVIVED",
                                ([status] if status not in ("ok", "failed") else []) + failed, time.time() - start))
            finally:
                with open(path, "w") as f:
                    f.write(original)
            print(f"mutation_check: {m.name}: {results[-1][1]} ({results[-1][3]:.0f} s)", file=sys.stderr)
    finally:
        log.close()
        if not opt.keep:
            shutil.rmtree(tree, ignore_errors=True)

    if opt.markdown:
        print("| mutation | what is wrong | caught by (failing tests) |")
        print("|---|---|---|")
        for m, verdict, tests, _ in results:
            caught = ", ".join(f"`{t}`" if "." in t else t for t in tests) if tests else ""
            print(f"| `{m.name}` | {m.what} | {verdict if verdict != 'caught' else ''}{caught} |")
    else:
        for m, verdict, tests, seconds in results:
            print(f"{m.name:28s} {verdict:10s} {seconds:5.0f} s  {' '.join(tests)}")
    bad = [m.name for m, verdict, _, _ in results if verdict != "caught"]
    if bad:
        print(f"mutation_check: not caught: {', '.join(bad)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
