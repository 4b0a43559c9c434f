"""Run a sweep on Dask: warm-start chains as chained tasks, every finished point persisted at once.

Execution: an embedded ``dask.distributed.LocalCluster`` (worker processes with one thread
each; ``workers`` defaults to the number of cores) or an existing cluster given by its
scheduler address (``tcp://HOST:PORT``). Each point is one task
(:func:`fdm_awe.sweep.runner.run_point`); the next point of its chain takes the task's output
as an argument, so Dask runs a chain in order (normally on one worker, where the data is) and
different chains in parallel. Chains starting at lower winds get a higher Dask priority (see
:func:`chain_priorities`); the order changes when a point is computed, never its result.

The client writes each point's record as soon as its task finishes
(:class:`~fdm_awe.sweep.store.PointStore`), so an interrupted sweep resumes without
recomputing finished points. Points already on disk are skipped; ``retry_failed`` recomputes
recorded failures.

Outcome (:class:`SweepRun`): ``complete`` is True when every point of the sweep has a record
(``ok`` or ``failed``). Points whose task could not run at all (a worker died, the sweep was
stopped) are listed in ``errors`` and are not persisted: a rerun computes them.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from ..errors import InputError
from .runner import FailedUpstream, run_point
from .spec import Chain, Point, SweepSpec, chains
from .store import PointStore


@dataclass
class SweepRun:
    """What a sweep run did (counts of points) and every finished record of the sweep."""

    n_points: int  #: points in the sweep
    n_cached: int  #: finished before this run (not recomputed)
    n_computed: int = 0  #: finished in this run (ok or failed)
    n_failed_now: int = 0  #: of those, failed
    errors: list[tuple[str, str]] = field(default_factory=list)  #: (point label, reason) of points that did not run
    wall_s: float = 0.0  #: wall time of the computation [s] (cluster start-up excluded)
    startup_s: float = 0.0  #: cluster start-up time [s]
    workers: int = 0
    scheduler: str = ""
    stopped: bool = False  #: stopped early (``stop_after``)
    records: dict[str, dict[str, Any]] = field(default_factory=dict)  #: id -> record, sweep points only
    computed_ids: list[str] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return len(self.records) == self.n_points

    @property
    def n_failed(self) -> int:
        return sum(1 for r in self.records.values() if r.get("status") != "ok")


#: Dask settings of the embedded LocalCluster (an external cluster, ``--scheduler``, is configured
#: by its owner). None of them changes what a point computes.
#:
#: - ``worker-saturation`` 1.0: a worker holds one queued root task (an anchor) at a time, not
#:   two (Dask's default 1.1 rounds up to 2 per single-threaded worker), so the first anchors go
#:   to different workers instead of both waiting on the first worker that registered.
#: - the rest removes background CPU load. With as many workers as cores, every CPU second the
#:   cluster spends besides the points is taken from a worker; with fewer workers it runs on an
#:   idle core. Measured on a 2-core machine (8 points, mesh 10/8, 2 workers,
#:   ``scripts/profile_sweep.py``, three runs each): Dask itself used 0.23 cores of the 2 (each
#:   worker's statistical profiler sampling every 10 ms, event-loop health ticks every 20 ms in
#:   the scheduler, the nannies and the workers, memory monitors every 100 ms, system monitors
#:   every 500 ms), 0.07 cores with these settings. The profiler (``distributed.worker.profile``)
#:   only feeds the dashboard's profile page; the ticks only detect a blocked event loop
#:   (warning after 3 s); the monitors guard the memory limits (checked every second instead of
#:   ten times a second) and feed dashboard metrics.
#: - ``MALLOC_TRIM_THRESHOLD_`` is not set in the worker processes: with Dask's 64 kB the C
#:   library hands freed memory back to the system at once and maps every large block anew
#:   (4.4 times the page faults; the workers' system CPU of that sweep 1.3-1.5 s instead of
#:   0.1-0.2 s). With the C library's default, freed memory is kept for reuse (peak memory of
#:   a process solving two points 145 MB instead of 142 MB); results are bit-identical either way. The single-threaded BLAS/OpenMP settings of
#:   ``distributed.nanny.pre-spawn-environ`` stay.
LOCAL_CLUSTER_CONFIG: dict[str, Any] = {
    "distributed.scheduler.worker-saturation": 1.0,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "500ms",
    "distributed.admin.tick.cycle": "5s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
}


@contextlib.contextmanager
def sigint_ignored() -> Any:
    """Ctrl-C (SIGINT) is ignored in this block, by this process and by the processes it starts
    meanwhile (SIG_IGN is inherited by child processes).

    Used twice. Around the local cluster's start-up (a few seconds): Ctrl-C in a terminal goes
    to the whole process group, and worker processes that did not ignore it would each print a
    KeyboardInterrupt traceback while this process shuts the cluster down. Around the shutdown
    (bounded by Dask's timeouts): a second Ctrl-C would interrupt it half-way and leave Dask to
    print tracebacks from its exit handlers. Only the main thread can change signal handlers;
    elsewhere the block runs unchanged.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def start_client(workers: int | None, scheduler: str | None) -> tuple[Any, Any, int]:
    """A Dask client: ``(client, cluster or None, workers)``, on the ``tcp://`` ``scheduler`` or an
    embedded LocalCluster of ``workers`` processes (None: one per core)."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
        n = len(client.scheduler_info().get("workers", {}))
        if n == 0:
            client.wait_for_workers(1, timeout=60)
            n = len(client.scheduler_info().get("workers", {}))
        return client, None, n
    n = workers or os.cpu_count() or 1
    if n < 1:
        raise InputError(f"workers = {n} out of range (allowed >= 1)")
    # the scheduler always serves HTTP (health routes): a free port avoids clashes with other clusters
    import dask

    # the config is read by the scheduler, the nannies and (passed on) the workers
    with dask.config.set(LOCAL_CLUSTER_CONFIG), sigint_ignored():
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0",
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster, n


def run_sweep(spec: SweepSpec, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
              retry_failed: bool = False, progress: bool = True, stop_after: int | None = None,
              on_point: Callable[[dict[str, Any]], None] | None = None, warm_start: bool = True) -> SweepRun:
    """Compute the missing points of ``spec`` into ``out_dir`` (see the module docstring).

    ``warm_start=False`` solves every point cold, as an independent task (for comparison).

    ``stop_after``: stop (cancel the remaining tasks) once this many points were finished in
    this run, as an interruption would. ``on_point`` is called with each new record.
    """
    points = spec.validate().points()
    store = PointStore(out_dir)
    ids = [p.id for p in points]
    done = store.records(ids)
    if retry_failed:
        for pid, r in list(done.items()):
            if r.get("status") != "ok":
                store.forget(pid)
                del done[pid]
    run = SweepRun(n_points=len(points), n_cached=len(done))
    pending = [p for p in points if p.id not in done]
    if not pending:
        run.records = done
        return run

    t0 = time.perf_counter()
    client, cluster, n = start_client(workers, scheduler)
    run.startup_s = time.perf_counter() - t0
    run.workers = n
    run.scheduler = scheduler or "local"
    t1 = time.perf_counter()
    try:
        chain_list = chains(points, spec.anchor_every) if warm_start else [Chain((p,)) for p in points]
        futures, by_key = _submit(client, chain_list, done, store)
        _collect(futures, by_key, store, run, done, progress, stop_after, on_point, client)
    finally:
        with sigint_ignored():  # after Ctrl-C: shut down quietly, whatever the user presses
            client.close()
            if cluster is not None:
                cluster.close()
    run.wall_s = time.perf_counter() - t1
    run.records = {pid: done[pid] for pid in ids if pid in done}
    return run


def chain_priorities(chain_list: list[Chain]) -> list[int]:
    """Dask priority of each chain (higher runs first): cold-started chains by ascending wind of
    their first point (ties in list order); a seeded chain has the priority of its seed.

    Low winds first: near the cut-in wind cycles are marginal and their solves the longest
    (and failures use the whole budget), so starting them first keeps one long chain from
    finishing alone at the end while the other workers are idle.
    """
    roots = sorted((i for i, c in enumerate(chain_list) if c.after is None), key=lambda i: (chain_list[i].points[0].wind, i))
    prio = {i: len(roots) - rank for rank, i in enumerate(roots)}
    out = []
    for i, c in enumerate(chain_list):
        j = i
        while chain_list[j].after is not None:
            j = chain_list[j].after
        out.append(prio[j])
    return out


def _submit(client: Any, chain_list: list, done: dict[str, dict], store: PointStore) -> tuple[list, dict[str, Point]]:
    """Submit every missing point, chained to its warm-start predecessor (a future, a stored
    warm start, a stored failure, or nothing)."""
    from dask.distributed import Future

    after_point: dict[str, Any] = {}  # point id -> warm start for the next point (Warm, Future or None)
    futures = []
    by_key: dict[str, Point] = {}
    for ch, prio in zip(chain_list, chain_priorities(chain_list)):
        cur = None if ch.after is None else after_point[chain_list[ch.after].points[0].id]
        for p in ch.points:
            rec = done.get(p.id)
            if rec is not None:
                if rec.get("status") == "ok":
                    w = store.load_warm(p.id)
                    if w is not None:
                        w.family = rec.get("family")  # the start family its chain carries on
                        cur = w
                elif not isinstance(cur, Future):  # failed on disk: the next point is told so
                    cur = FailedUpstream(cur.warm if isinstance(cur, FailedUpstream) else cur)
            else:
                key = f"sweep-point-{p.id}"
                fut = client.submit(run_point, p, cur, key=key, pure=False, retries=0, priority=prio)
                futures.append(fut)
                by_key[fut.key] = p
                cur = fut
            after_point[p.id] = cur
    return futures, by_key


def _collect(futures: list, by_key: dict[str, Point], store: PointStore, run: SweepRun, done: dict[str, dict],
             progress: bool, stop_after: int | None, on_point: Callable | None, client: Any) -> None:
    from dask.distributed import as_completed
    from tqdm import tqdm

    remaining = len(futures)
    bar = tqdm(total=remaining, unit="pt", desc="sweep", file=sys.stderr, disable=not progress, dynamic_ncols=True)
    failed = 0

    def post() -> None:
        bar.set_postfix_str(f"done {run.n_computed} failed {failed} remaining {remaining}", refresh=True)

    post()
    try:
        for fut in as_completed(futures):
            p = by_key[fut.key]
            remaining -= 1
            try:
                rec, warm = fut.result()
            except Exception as exc:  # the task did not run (worker lost, upstream lost, cancelled)
                run.errors.append((p.label(), f"{type(exc).__name__}: {exc}".splitlines()[0]))
                bar.update(1)
                post()
                continue
            store.write(rec, warm)
            done[p.id] = rec
            run.n_computed += 1
            run.computed_ids.append(p.id)
            if rec["status"] != "ok":
                failed += 1
                run.n_failed_now += 1
            bar.update(1)
            post()
            if on_point is not None:
                on_point(rec)
            if stop_after is not None and run.n_computed >= stop_after and remaining > 0:
                run.stopped = True
                client.cancel([f for f in futures if not f.done()])
                break
    finally:
        bar.close()
