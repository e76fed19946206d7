#!/usr/bin/env python3
"""Runs `grainlab run` cases: locally in a pool of processes, or on a Dask distributed cluster.

Every case is one `grainlab run CONFIG --out DIR --quiet [--threads T] --set KEY=VALUE ...` of the
executable, started with an argument vector (never a shell). Used two ways:

  * as a module by the calibration driver (tools/calibrate.py): LocalRunner / DaskRunner;
  * as a program by `grainlab sweep --scheduler tcp://HOST:PORT`:
        dask_runner.py sweep MANIFEST.json RESULTS.json
    MANIFEST (written by src/cli/sweep_dask.cpp) names the scheduler, the executable, the config and
    the cases; RESULTS receives each case's exit code, attempts and workers, or an error.

On a cluster a case's results folder either is written straight to a path every worker sees
(shared_out) or is written in the worker's scratch space and sent back as a tar archive. A worker
lost mid-case makes the scheduler run the case again on another worker; each start of a case is
logged as a scheduler event, so the results say how many attempts a case took and where.
docs/scale-out.md describes the set-up."""
import io
import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import tarfile
import tempfile
import threading
import time
import uuid
from concurrent.futures import CancelledError, ThreadPoolExecutor, as_completed

EVENT_TOPIC = "grainlab-run-start"
# Cases whose task raised (e.g. no grainlab executable on that worker) are tried again elsewhere;
# a worker that dies is handled by the scheduler (distributed.scheduler.allowed-failures).
TASK_RETRIES = 2
WORKER_WAIT_S = 300


class ClusterLost(ConnectionError):
    """The scheduler went away mid-way: the cases reported until then stand, the others were not run."""


class Stopped(BaseException):
    """SIGTERM or SIGHUP reached the runner (raised in the main thread, like KeyboardInterrupt for SIGINT)."""


def stop_on_signals():
    """SIGTERM and SIGHUP raise Stopped in the main thread, so the runner ends its runs and reports."""
    def handler(sig, frame):
        raise Stopped(signal.Signals(sig).name)
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, handler)



def case_argv(executable, config, out_dir, threads, sets):
    """The argument vector of one case: the same as the local sweep's."""
    argv = [executable, "run", config, "--out", out_dir, "--quiet"]
    if threads:
        argv += ["--threads", str(threads)]
    for assignment in sets:
        argv += ["--set", assignment]
    return argv


def _child_argv(argv):
    # setpriv --pdeathsig KILL: the run dies with the process that started it, so a killed worker
    # or driver leaves no orphaned run writing into a folder that is being run again.
    setpriv = shutil.which("setpriv")
    return [setpriv, "--pdeathsig", "KILL", "--", *argv] if setpriv else argv


def run_case(job):
    """Runs one case (on a Dask worker, or locally when job["mode"] == "local").

    job: executable, config, config_text (the config file's text, or None for a preset), name,
    sets, threads (0: the config's solver.threads locally, 1 on a worker), out (the client's results
    folder of the case), mode ("local", "shared" or "return"), token (the run's unique id, for the attempt log).
    Returns a dict: name, exit_code, log, worker, host, files (tar.gz bytes in "return" mode)."""
    worker = None
    if job["mode"] != "local":
        from distributed import get_worker
        worker = get_worker()
        worker.log_event(EVENT_TOPIC, {"token": job["token"], "name": job["name"], "worker": worker.address})
    executable = job["executable"]
    if not os.access(executable, os.X_OK):
        executable = shutil.which("grainlab")
        if executable is None:
            raise RuntimeError(f"{socket.gethostname()}: neither {job['executable']} nor a grainlab on PATH")
    # On a cluster a case runs on one thread unless told otherwise: a worker's task slots are its
    # share of the cores, and OpenMP beyond the free cores runs many times slower (measured 20-30x
    # on a shared 2-core host: 180-300 s for a 10 s case).
    threads = job["threads"] or (1 if worker else 0)
    scratch = None
    config = job["config"]
    if not config.startswith("preset:") and not os.path.exists(config):
        # The config's path does not exist here: use the text the client sent (files the config
        # names must then be on a path every worker sees; docs/scale-out.md).
        scratch = tempfile.mkdtemp(prefix="grainlab-", dir=worker.local_directory if worker else None)
        config = os.path.join(scratch, "config.toml")
        with open(config, "w") as f:
            f.write(job["config_text"])
    out = job["out"]
    if job["mode"] == "local":
        run_dir = out
    elif job["mode"] == "shared":
        # Each attempt writes its own folder, renamed into place when complete: an attempt on a
        # lost worker never mixes files with the one that replaced it.
        run_dir = os.path.join(os.path.dirname(out), ".attempts", f"{job['name']}-{uuid.uuid4().hex[:8]}")
    else:
        scratch = scratch or tempfile.mkdtemp(prefix="grainlab-", dir=worker.local_directory)
        run_dir = os.path.join(scratch, "case")
    if os.path.exists(run_dir):
        shutil.rmtree(run_dir)
    os.makedirs(os.path.dirname(os.path.abspath(run_dir)), exist_ok=True)
    started = time.time()
    proc = subprocess.Popen(_child_argv(case_argv(executable, config, run_dir, threads, job["sets"])),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    registry = job.get("registry")  # LocalRunner's (local mode only: it does not travel)
    if registry is not None:
        registry.started(proc)
    try:
        output, _ = proc.communicate()
    finally:
        if registry is not None:
            registry.finished(proc)
    result = {"name": job["name"], "exit_code": proc.returncode, "log": output.decode(errors="replace"),
              "worker": worker.address if worker else "local", "host": socket.gethostname(),
              "started": started, "finished": time.time(), "files": None}
    try:
        if job["mode"] == "shared":
            if os.path.exists(out):
                shutil.rmtree(out)
            if os.path.exists(run_dir):
                os.replace(run_dir, out)
        elif job["mode"] == "return" and os.path.exists(run_dir):
            buffer = io.BytesIO()
            with tarfile.open(fileobj=buffer, mode="w:gz", compresslevel=3) as tar:
                tar.add(run_dir, arcname=".")
            result["files"] = buffer.getvalue()
    finally:
        if scratch:
            shutil.rmtree(scratch, ignore_errors=True)
    return result


def _unpack(files, out):
    """Unpacks a case's results folder sent back by a worker into out (replacing what was there)."""
    incoming = f"{out}.incoming-{uuid.uuid4().hex[:8]}"
    with tarfile.open(fileobj=io.BytesIO(files), mode="r:gz") as tar:
        for member in tar.getmembers():
            name = os.path.normpath(member.name)
            if name.startswith("..") or os.path.isabs(name) or not (member.isfile() or member.isdir()):
                raise RuntimeError(f"results of {out}: unexpected archive member {member.name!r}")
        tar.extractall(incoming)
    if os.path.exists(out):
        shutil.rmtree(out)
    os.replace(incoming, out)


class LocalRunner:
    """Runs cases as local processes, `jobs` at a time."""

    def __init__(self, jobs):
        self.jobs = jobs
        self._procs = set()  # the runs in progress, ended when the runner is stopped
        self._lock = threading.Lock()
        self._stopping = False

    def started(self, proc):
        with self._lock:
            self._procs.add(proc)
            if self._stopping:  # started while the runner was being stopped
                proc.kill()

    def finished(self, proc):
        with self._lock:
            self._procs.discard(proc)

    def run(self, jobs, on_done):
        """Runs every job; calls on_done(job, result) in this thread as each one completes. Stopped
        (a signal, KeyboardInterrupt, an exception of on_done), it ends the runs in progress first:
        none is left writing into its folder after this returns."""
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            futures = {pool.submit(run_case, dict(job, mode="local", registry=self)): job for job in jobs}
            try:
                for future in as_completed(futures):
                    job = futures[future]
                    result = future.result()
                    result["attempts"] = 1
                    result["workers"] = ["local"]
                    on_done(job, result)
            except BaseException:
                for future in futures:
                    future.cancel()
                with self._lock:
                    self._stopping = True
                    for proc in self._procs:
                        proc.kill()
                raise

    def close(self):
        pass


class DaskRunner:
    """Runs cases on the workers of a Dask distributed scheduler."""

    def __init__(self, scheduler, shared_out=False, quiet=False, notices=None):
        import cloudpickle
        import dask
        from distributed import Client
        # The worker needs run_case but not this file: its module travels by value.
        cloudpickle.register_pickle_by_value(sys.modules[__name__])
        self.shared_out = shared_out
        self.address = scheduler
        # Dask's own connect timeout (distributed.comm.timeouts.connect, 30 s unless configured, e.g.
        # DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=5s).
        timeout = dask.config.get("distributed.comm.timeouts.connect")
        try:
            self.client = Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError) as e:
            raise ConnectionError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        if not self.client.scheduler_info()["workers"]:
            if not quiet:
                print(f"waiting up to {WORKER_WAIT_S} s for a worker to join {scheduler}", file=notices or sys.stderr)
            try:
                self.client.wait_for_workers(1, timeout=WORKER_WAIT_S)
            except TimeoutError:
                self.client.close()
                raise ConnectionError(f"no Dask worker joined {scheduler} within {WORKER_WAIT_S} s") from None

    def run(self, jobs, on_done):
        from distributed import as_completed as dask_completed
        futures = {}
        for job in jobs:
            task = dict(job, mode="shared" if self.shared_out else "return", token=uuid.uuid4().hex)
            future = self.client.submit(run_case, task, key=f"grainlab-{job['name']}-{task['token'][:8]}",
                                        pure=False, retries=TASK_RETRIES)
            futures[future] = (job, task["token"])
        for future in dask_completed(list(futures), loop=self.client.loop):
            job, token = futures[future]
            try:
                result = future.result()
            except CancelledError:
                # Cancelled by the client: the scheduler is gone, and with it every case not reported yet.
                raise ClusterLost(f"the Dask scheduler {self.address} was lost") from None
            except Exception as e:  # the task itself raised on every try: no run took place
                result = {"name": job["name"], "exit_code": 127, "log": f"{type(e).__name__}: {e}\n", "files": None,
                          "worker": "", "host": ""}
            try:
                starts = [msg for _, msg in self.client.get_events(EVENT_TOPIC) if msg.get("token") == token]
            except (OSError, CancelledError) as e:
                raise ClusterLost(f"the Dask scheduler {self.address} was lost ({type(e).__name__})") from None
            if result["files"] is not None:
                _unpack(result["files"], job["out"])
            result["files"] = None
            result["attempts"] = max(1, len(starts))
            result["workers"] = [msg["worker"] for msg in starts]
            on_done(job, result)
        if self.shared_out:
            # What is left there are the folders of attempts whose worker was lost.
            for parent in {os.path.dirname(job["out"]) for job in jobs}:
                shutil.rmtree(os.path.join(parent, ".attempts"), ignore_errors=True)

    def close(self):
        try:
            self.client.close(timeout=10)
        except Exception:  # a scheduler that is gone: nothing to close there
            pass


def _quiet_dask_logs(folder):
    """Everything Dask and Python write to stderr (reconnection attempts, a lost scheduler's
    tracebacks) goes to FOLDER/dask-client.log instead of the terminal, where the sweep says in one
    line what happened. Returns the terminal's stderr, for the runner's own progress lines."""
    terminal = os.fdopen(os.dup(2), "w", buffering=1)
    log = open(os.path.join(folder, "dask-client.log"), "a", buffering=1)
    os.dup2(log.fileno(), 2)
    sys.stderr = log
    return terminal


def _sweep(manifest_path, results_path):
    """`grainlab sweep --scheduler`: runs the manifest's cases and writes each one's outcome."""
    with open(manifest_path) as f:
        manifest = json.load(f)
    config_text = None
    if not manifest["config"].startswith("preset:"):
        with open(manifest["config"]) as f:
            config_text = f.read()
    jobs = [{"executable": manifest["executable"], "config": manifest["config"], "config_text": config_text,
             "name": case["name"], "sets": case["sets"], "threads": manifest["threads"],
             "out": os.path.join(manifest["out"], case["name"])} for case in manifest["cases"]]
    outcome = {}

    def write(results):
        tmp = results_path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(results, f, indent=1)
        os.replace(tmp, results_path)

    def done(job, result):
        with open(os.path.join(manifest["out"], job["name"] + ".log"), "w") as f:
            f.write(result["log"])
        outcome[job["name"]] = {"exit_code": result["exit_code"], "attempts": result["attempts"],
                                "workers": result["workers"]}
        # Written as each case finishes: what finished is known however the runner ends.
        write({"cases": outcome})
        if not manifest["quiet"]:
            status = "completed" if result["exit_code"] == 0 else f"failed (exit {result['exit_code']})"
            again = f" after {result['attempts']} attempts ({' then '.join(result['workers'])})" \
                if result["attempts"] > 1 else ""
            print(f"[{len(outcome)}/{len(jobs)}] {job['name']}: {status} on {result['worker']}{again}",
                  file=terminal, flush=True)

    # Whatever ends the runner -- a scheduler that cannot be reached or goes away, a signal, an
    # error -- it writes the cases that finished and one line saying why the others did not; the
    # sweep makes its table from that (no traceback).
    stop_on_signals()
    terminal = _quiet_dask_logs(manifest["out"])
    runner = None
    try:
        runner = DaskRunner(manifest["scheduler"], shared_out=manifest["shared_out"], quiet=manifest["quiet"],
                            notices=terminal)
        runner.run(jobs, done)
    except ConnectionError as e:
        write({"cases": outcome, "error": str(e)})
        return 1
    except KeyboardInterrupt:
        write({"cases": outcome, "error": "interrupted (SIGINT)"})
        return 130
    except Stopped as e:
        write({"cases": outcome, "error": f"interrupted ({e})"})
        return 143
    except Exception as e:
        write({"cases": outcome, "error": f"the Dask runner failed: {type(e).__name__}: {e}"})
        return 1
    finally:
        if runner is not None:
            runner.close()
    write({"cases": outcome})
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[1] != "sweep":
        sys.exit(__doc__)
    sys.exit(_sweep(sys.argv[2], sys.argv[3]))
