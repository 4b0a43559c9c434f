#!/usr/bin/env python3
"""Where the CPU of a sweep on the embedded Dask cluster goes, per process (and per thread).

Runs one small sweep (default 4 points of one line, mesh 10/8, anchors every 2 winds,
``--warm-fallback one``, 2 local workers) into a temporary folder while a sampler thread reads
the CPU seconds (user + system, and system alone) of this process, of its threads and of every
process below it every 0.25 s, and the whole machine's busy / idle / steal seconds. Reports for
the computation window (cluster start-up excluded, as in ``scripts/bench_sweep.py``):

- CPU seconds per process: the client process (it also runs the embedded scheduler and the
  nannies, which live in its event loop; split into its threads), each worker process (split
  into the thread that ran the points and the rest: event loop, heartbeats, monitors,
  profiler if enabled), any other helper process (multiprocessing's resource tracker), and
  what the rest of the machine used meanwhile;
- the CPU not spent by the point threads, in cores, over the whole window and its second half;
- per worker: seconds from the start of the computation to the start of its first point
  (task transfer, unpickling, imports), and of that first point the seconds outside IPOPT
  next to its build time (NLP transcription and IPOPT instances created);
- the points' own CPU seconds (summed ``cpu_s`` of the records: the worker process's CPU
  while it ran the point, all its threads) and the results (to compare runs).

CPU seconds [s], wall seconds [s]. The numbers depend on how busy the machine is.

Usage: scripts/profile_sweep.py [--wind 7:10:1] [--mesh 10,8] [--workers 2] [--anchor-every 2]
       [--warm-fallback one] [--json profile_sweep.json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import threading
import time

import psutil

from fdm_awe.ocp.problem import Mesh
from fdm_awe.sweep.execute import run_sweep
from fdm_awe.sweep.spec import SweepSpec, parse_floats, parse_tether_ranges

#: sampling period of the process tree [s]
SAMPLE_S = 0.25


class TreeSampler:
    """CPU seconds (user + system) of this process, its threads, and every descendant process,
    sampled every :data:`SAMPLE_S` seconds: ``samples`` is a list of ``(t, {key: cpu_s})``
    where ``t`` is ``time.perf_counter()`` [s] and a key is ``(pid, tid)`` (tid 0: the whole process)."""

    def __init__(self) -> None:
        self.me = psutil.Process()
        self.samples: list[tuple[float, dict[tuple[int, int], float]]] = []
        self.info: dict[int, dict] = {}  # pid -> parent pid, create time, command line
        self.thread_names: dict[int, str] = {}  # native id -> name, threads of this process
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="profile-sweep-sampler", daemon=True)

    def start(self) -> "TreeSampler":
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def sample(self) -> None:
        t = time.perf_counter()
        self.thread_names.update((th.native_id, th.name) for th in threading.enumerate())
        snap: dict[tuple[int, int], float] = {}
        procs = [self.me]
        try:
            procs += self.me.children(recursive=True)
        except psutil.Error:
            pass
        for p in procs:
            try:
                with p.oneshot():
                    ct = p.cpu_times()
                    snap[(p.pid, 0)] = ct.user + ct.system
                    snap[(p.pid, -1)] = ct.system
                    for th in p.threads():
                        snap[(p.pid, th.id)] = th.user_time + th.system_time
                    if p.pid not in self.info:
                        self.info[p.pid] = {"ppid": p.ppid(), "create_time": p.create_time(),
                                            "cmdline": " ".join(p.cmdline())[:160]}
            except psutil.Error:
                continue
        # the whole machine (key (-1, field)): busy, idle and steal seconds from /proc/stat
        try:
            with open("/proc/stat") as fh:
                v = [int(x) for x in fh.readline().split()[1:]]
            tck = os.sysconf("SC_CLK_TCK")
            snap[(-1, 0)] = (v[0] + v[1] + v[2] + v[5] + v[6] + v[7]) / tck
            snap[(-1, 1)] = (v[3] + v[4]) / tck
            snap[(-1, 2)] = v[7] / tck
        except (OSError, ValueError, IndexError):
            pass
        self.samples.append((t, snap))

    def _loop(self) -> None:
        while not self._stop.is_set():
            self.sample()
            self._stop.wait(SAMPLE_S)


def roles(info: dict[int, dict], me: int, worker_pids: set[int]) -> dict[int, str]:
    """Role of every process: the client (this one; it also runs the embedded scheduler and
    the nannies' event loop), the workers (the processes that ran points), other (e.g.
    multiprocessing's resource tracker)."""
    return {pid: "client+scheduler" if pid == me else "worker" if pid in worker_pids else "other" for pid in info}


def window(samples: list, t_a: float, t_b: float) -> dict[tuple[int, int], float]:
    """CPU seconds of every key between ``t_a`` and ``t_b``: each key's last value sampled up to
    ``t_b`` minus its last value sampled up to ``t_a`` (0 for a process or thread that did not
    exist yet; one that ended counts up to its last sample). The end of the computation is
    sampled when the last point arrives, so the cluster's shutdown is not counted."""
    before: dict[tuple[int, int], float] = {}
    last: dict[tuple[int, int], float] = {}
    for t, snap in samples:
        if t <= t_a:
            before.update(snap)
        if t <= t_b:
            last.update(snap)
    return {k: v - before.get(k, 0.0) for k, v in last.items()}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wind", default="7:10:1", help="wind speeds [m/s] (default 7:10:1)")
    ap.add_argument("--tether-range", default="200:250", help="reel-out ranges (default 200:250)")
    ap.add_argument("--mesh", default="10,8", help="NGEN,NREC (default 10,8)")
    ap.add_argument("--workers", type=int, default=2, help="local workers (default 2)")
    ap.add_argument("--anchor-every", type=int, default=2, help="chain layout (default 2)")
    ap.add_argument("--warm-fallback", default="one", choices=("all", "one", "none"))
    ap.add_argument("--json", default=None, help="write the numbers to this JSON file")
    args = ap.parse_args()
    ng, nr = (int(v) for v in args.mesh.split(","))
    spec = SweepSpec(winds=parse_floats(args.wind, "--wind", "m/s"), configs=("nominal",),
                     tether_ranges=parse_tether_ranges(args.tether_range), mesh=Mesh(n_gen=ng, n_rec=nr),
                     anchor_every=args.anchor_every, warm_fallback=args.warm_fallback).validate()
    done_at: dict[str, float] = {}
    sampler = TreeSampler().start()
    with tempfile.TemporaryDirectory(prefix="profile_sweep_") as tmp:
        t0 = time.perf_counter()

        def on_point(rec: dict) -> None:
            done_at[rec["id"]] = time.perf_counter()
            sampler.sample()

        r = run_sweep(spec, tmp, workers=args.workers, progress=False, on_point=on_point)
        t_end = time.perf_counter()
    sampler.stop()
    t_a = t0 + r.startup_s
    t_b = max(done_at.values())
    cpu = window(sampler.samples, t_a, t_b)
    me = os.getpid()
    thread_names = sampler.thread_names
    recs = list(r.records.values())
    by_worker: dict[int, list[dict]] = {}
    for x in recs:
        by_worker.setdefault(int(x["worker"].rsplit(":", 1)[1]), []).append(x)
    role = roles(sampler.info, me, set(by_worker))
    out: dict = {"n_points": len(recs), "workers": r.workers, "wall_s": r.wall_s, "startup_s": r.startup_s,
                 "close_s": t_end - t0 - r.startup_s - r.wall_s, "window_s": t_b - t_a,
                 "sum_point_cpu_s": sum(x["cpu_s"] or 0.0 for x in recs),
                 "sum_point_solve_s": sum(x["solve_s"] or 0.0 for x in recs),
                 "results": {x["id"]: [x["wind_mps"], x["status"], x["P_avg_W"], x["iterations"], x["warm_from"]] for x in recs},
                 "processes": [], "workers_detail": []}
    print(f"{len(recs)} points on {r.workers} worker(s): start-up {r.startup_s:.1f} s, computation {r.wall_s:.1f} s "
          f"(CPU window {t_b - t_a:.1f} s), close {out['close_s']:.1f} s")
    print(f"summed point CPU {out['sum_point_cpu_s']:.1f} s, of which IPOPT {out['sum_point_solve_s']:.1f} s (wall)")
    total = 0.0
    if (-1, 0) in cpu:
        out["machine"] = {"busy_s": cpu[(-1, 0)], "idle_s": cpu[(-1, 1)], "steal_s": cpu[(-1, 2)]}
        print(f"  machine: busy {cpu[(-1, 0)]:.2f} s (steal {cpu[(-1, 2)]:.2f} s), idle {cpu[(-1, 1)]:.2f} s")
    for pid in sorted(role, key=lambda p: (role[p], p)):
        c = cpu.get((pid, 0), 0.0)
        total += c
        threads = sorted(((cpu[k], k[1]) for k in cpu if k[0] == pid and k[1] > 0), reverse=True)
        entry = {"pid": pid, "role": role[pid], "cpu_s": c, "threads": [[thread_names.get(tid, str(tid)), s] for s, tid in threads if s > 0.005]}
        out["processes"].append(entry)
        entry["system_s"] = cpu.get((pid, -1), 0.0)
        line = f"  {role[pid]:17s} pid {pid}: {c:6.2f} s CPU (system {entry['system_s']:.2f} s)"
        if role[pid] == "worker" and threads:
            line += f" (point thread {threads[0][0]:.2f} s, rest {c - threads[0][0]:.2f} s: " + \
                ", ".join(f"{s:.2f}" for s, _ in threads[1:] if s > 0.005) + ")"
        elif role[pid] == "client+scheduler":
            line += " (" + ", ".join(f"{thread_names.get(tid, tid)} {s:.2f}" for s, tid in threads if s > 0.005) + ")"
        print(line)
    out["total_cpu_s"] = total
    print(f"  total {total:.2f} s CPU in {t_b - t_a:.1f} s on {os.cpu_count()} cores"
          + (f"; other processes of the machine {cpu[(-1, 0)] - total:.2f} s" if (-1, 0) in cpu else ""))
    # CPU not spent by the threads that ran points, per second of computation: over the whole
    # window and over its second half (after most of the imports and first builds)
    point_tids = {max((k for k in cpu if k[0] == pid and k[1] > 0), key=cpu.get) for pid in by_worker}
    for name, a in (("whole", t_a), ("second half", 0.5 * (t_a + t_b))):
        c = window(sampler.samples, a, t_b)
        tot = sum(v for k, v in c.items() if k[1] == 0 and k[0] > 0)
        pts = sum(c.get(k, 0.0) for k in point_tids)
        by_role = {rl: sum(v for k, v in c.items() if k[1] == 0 and role.get(k[0]) == rl) for rl in set(role.values())}
        by_role["worker (not the point thread)"] = by_role.get("worker", 0.0) - pts
        smp = sum(v for k, v in c.items() if k[0] == me and thread_names.get(k[1]) == "profile-sweep-sampler")
        by_role["client+scheduler"] = by_role.get("client+scheduler", 0.0) - smp
        by_role["sampler (this measurement)"] = smp
        by_role.pop("worker", None)
        rate = {k: v / (t_b - a) for k, v in by_role.items()}
        out[f"overhead_cores_{name.replace(' ', '_')}"] = rate
        print(f"  {name} window ({t_b - a:.1f} s): points {pts:.2f} s, everything else {tot - pts:.2f} s CPU = "
              f"{(tot - pts) / (t_b - a):.3f} cores (" + ", ".join(f"{k} {v:.3f}" for k, v in sorted(rate.items())) + ")")
    for pid, xs in sorted(by_worker.items()):
        xs.sort(key=lambda x: done_at[x["id"]])
        first = xs[0]
        start_first = done_at[first["id"]] - first["wall_s"] - t_a
        outside = first["wall_s"] - (first["solve_s"] or 0.0)
        d = {"pid": pid, "points": len(xs), "before_first_point_s": start_first, "first_point_wall_s": first["wall_s"],
             "first_point_outside_solver_s": outside, "first_point_build_s": first["build_s"],
             "busy_s": sum(x["wall_s"] for x in xs), "cpu_s": sum(x["cpu_s"] for x in xs),
             "later_points_outside_solver_s": sum(x["wall_s"] - (x["solve_s"] or 0.0) for x in xs[1:])}
        out["workers_detail"].append(d)
        print(f"  worker {pid}: {len(xs)} points, first starts {start_first:.2f} s into the computation; first point "
              f"{first['wall_s']:.2f} s of which {outside:.2f} s outside IPOPT (build {first['build_s'] or 0:.2f} s); "
              f"later points {d['later_points_outside_solver_s']:.2f} s outside IPOPT; busy {d['busy_s']:.1f} s, CPU {d['cpu_s']:.1f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
