#!/usr/bin/env python3
"""The [W] beta study as a sweep on a two-worker Dask cluster and as a local sweep, compared cell by
cell (issue 14; the result is published in docs/scale-out.md).

    /usr/bin/python3 tools/cluster_vs_local.py --out /work/runs/beta-cluster [--exe build/grainlab]
        [--particles 2000] [--strain 0.03] [--betas 0,0.1,0.15,1,3,50] [--markdown FILE]

Starts `dask-scheduler` and two `dask-worker` processes (one task slot each) on 127.0.0.1, runs
`grainlab sweep preset:w-base --vary contact.beta=... --scheduler ADDRESS` with one thread per case,
then the same sweep locally (`--jobs 2`), stops the cluster, and compares the two sweep.csv tables:
every column but wall_seconds (and the cluster's attempts/workers) must be equal as text, and
every case's timeseries.csv byte for byte. Prints (or writes) a markdown table of both. Exit 0
when identical, 1 otherwise. Every process is started with an argument vector.
"""
import argparse
import contextlib
import csv
import os
import socket
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def two_worker_cluster(folder):
    os.makedirs(folder, exist_ok=True)
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = []

    def start(name, argv):
        log = open(os.path.join(folder, f"{name}.log"), "w")
        procs.append(subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL))

    try:
        start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"])
        deadline = time.time() + 60
        while True:
            with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=1):
                break
            if time.time() > deadline:
                raise RuntimeError("the scheduler did not start")
            time.sleep(0.2)
        for i in range(2):
            start(f"worker{i}", ["dask-worker", address, "--nthreads", "1", "--no-dashboard", "--name", f"w{i}",
                                 "--local-directory", os.path.join(folder, f"w{i}")])
        from distributed import Client
        with Client(address, timeout=30, set_as_default=False) as client:
            while len(client.scheduler_info()["workers"]) < 2:
                if time.time() > deadline:
                    raise RuntimeError("the workers did not join")
                time.sleep(0.2)
        yield address
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "grainlab"))
    ap.add_argument("--particles", type=int, default=2000)
    ap.add_argument("--strain", type=float, default=0.03)
    ap.add_argument("--betas", default="0,0.1,0.15,1,3,50")
    ap.add_argument("--markdown", help="write the markdown table here instead of stdout")
    a = ap.parse_args()
    sweep = [a.exe, "sweep", "preset:w-base", "--vary", f"contact.beta={a.betas}",
             "--set", f"sample.n_particles={a.particles}", "--set", f"test.final_axial_strain={a.strain}",
             "--set", "output.vtk_every_strain=0", "--threads", "1", "--quiet"]
    out = os.path.abspath(a.out)
    times = {}
    with two_worker_cluster(os.path.join(out, "cluster")) as address:
        t0 = time.time()
        subprocess.run([*sweep, "--scheduler", address, "--out", os.path.join(out, "dask")], check=True)
        times["dask"] = time.time() - t0
    t0 = time.time()
    subprocess.run([*sweep, "--jobs", "2", "--out", os.path.join(out, "local")], check=True)
    times["local"] = time.time() - t0

    local = read_table(os.path.join(out, "local", "sweep.csv"))
    remote = read_table(os.path.join(out, "dask", "sweep.csv"))
    skip = {"wall_seconds", "attempts", "workers"}
    differences = []
    for x, y in zip(local, remote):
        for k in x:
            if k not in skip and x[k] != y.get(k):
                differences.append(f"{x['case']}: {k} local {x[k]} cluster {y.get(k)}")
        with open(os.path.join(out, "local", x["case"], "timeseries.csv"), "rb") as f1, \
                open(os.path.join(out, "dask", y["case"], "timeseries.csv"), "rb") as f2:
            if f1.read() != f2.read():
                differences.append(f"{x['case']}: timeseries.csv differs")
    if len(local) != len(remote):
        differences.append(f"{len(local)} local cases, {len(remote)} on the cluster")

    cols = [("contact.beta", "β"), ("e0", "e0"), ("phi_peak_deg", "φp [°]"), ("phi_res_deg", "φres [°]"),
            ("psi_max_deg", "ψmax [°]"), ("E50_MPa", "E50 [MPa]")]
    cols = [(k, h) for k, h in cols if local and k in local[0]]
    lines = [f"| {' | '.join(h for _, h in cols)} | local: wall [s] | cluster: wall [s] | cluster: worker |",
             "|" + "---:|" * (len(cols) + 2) + "---|"]
    for x, y in zip(local, remote):
        cells = []
        for k, _ in cols:
            try:
                cells.append(f"{float(x[k]):.6g}" if x[k] == y.get(k) else f"{x[k]} ≠ {y.get(k)}")
            except ValueError:
                cells.append(x[k])
        lines.append(f"| {' | '.join(cells)} | {float(x['wall_seconds']):.0f} | {float(y['wall_seconds']):.0f} | "
                     f"{y.get('workers', '')} |")
    lines += ["", f"Whole sweeps: {times['dask']:.0f} s on the cluster, {times['local']:.0f} s locally (--jobs 2). "
              + ("Every column but wall_seconds is identical as text and every time series byte-identical."
                 if not differences else "DIFFERENCES: " + "; ".join(differences))]
    text = "\n".join(lines) + "\n"
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text)
    else:
        print(text)
    return 0 if not differences else 1


if __name__ == "__main__":
    sys.exit(main())
