"""Running tasks in parallel, each with a fresh OMPL, without paying for a fresh Python each time.

Every run gets a process of its own: a crash inside OMPL (a segmentation fault, an abort), the
kernel's out-of-memory killer or a run that ignores its deadline then costs one row, not the
batch, and no run inherits another's memory or OMPL state. Starting a whole Python for each run
costs about half a second (numpy, scipy, shapely and OMPL imports). Instead:

- a **warm worker** is a spawned process that has imported everything and loaded the problems it
  was given, but has never created an OMPL object;
- for each run it **forks a child**, which seeds OMPL first, solves, sends its row back through
  a pipe and exits; a fork of a warm worker costs milliseconds;
- a child that dies (a crash in OMPL, the kernel's out-of-memory killer) or overruns its time
  becomes an error row; the worker goes on with the next task. A worker that dies itself is
  replaced, and its task becomes an error row.

Where ``os.fork`` does not exist the worker starts a spawned process per run instead (correct,
slower). Inside a Dask worker, which runs threads (forking it is unsafe), each run is forked from
a fork server preloaded with the same imports (:func:`run_spawned` with ``warm=True``). Workers
and their children ignore Ctrl-C: the parent handles it, stops them and leaves its results file
valid.

Nothing outlives the process that started it, whatever kills that process (``kill -9``
included), so no orphan keeps a core busy for a whole time budget:

- on Linux every worker and every forked child asks the kernel to kill it when its parent dies
  (``prctl(PR_SET_PDEATHSIG, SIGKILL)``; the kernel sends it when the parent *thread* that
  started the process ends: the workers of :func:`run_local` are started by the thread iterating
  it, and are stopped before it returns anyway);
- everywhere a worker also watches its pipe to the parent while a child runs: the pipe closes
  when the parent dies, and the worker then kills the child and exits;
- the process a Dask worker starts for a run (its parent is the fork server, not the Dask
  worker) watches the Dask worker's pid from a thread and exits when it ends.
"""

from __future__ import annotations

import contextlib
import ctypes
import faulthandler
import functools
import multiprocessing as mp
import os
import pickle
import select
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from multiprocessing.connection import Connection, wait
from typing import Any

from ..foreign import describe_failure

__all__ = [
    "GRACE",
    "WARM_MODULES",
    "ChildFailure",
    "die_with_parent",
    "run_local",
    "run_once_in_child",
    "run_spawned",
]

#: Seconds a run may take beyond its budget before its child is killed (imports are done, so
#: this covers building the world, the optimum, and a slow machine).
GRACE = 120.0

#: ``prctl`` option that makes the kernel signal a process when its parent dies
#: (``<linux/prctl.h>``).
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int) -> None:
    """Make this process die with its parent ``parent`` (a pid), whatever kills the parent.

    On Linux the kernel sends SIGKILL to this process when the parent dies
    (``prctl(PR_SET_PDEATHSIG)``; strictly, when the parent's thread that created this process
    ends). A parent that died before the request is not seen by the kernel: then this process
    ends at once. Elsewhere this only does that check; the callers watch a pipe or a pid instead.
    """
    prctl = _prctl()
    if prctl is not None:
        prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


@functools.cache
def _prctl() -> Any:
    """libc's ``prctl`` on Linux (looked up once per process, so forked children inherit it),
    else None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


class _ParentGone(Exception):
    """The pipe to the parent closed (or spoke) while a child ran: the parent is gone."""


def run_once_in_child(fn: Callable[[Any], Any], task: Any, timeout: float,
                      watch: Connection | None = None) -> Any:  # fmt: skip
    """``fn(task)`` in a forked child (a spawned process without ``os.fork``); its return value,
    or an :class:`ChildFailure` describing how the child ended.

    ``watch``, a worker's pipe to its parent, is watched while the child runs: when it becomes
    readable (the parent died, or asks the worker to stop) the child is killed and
    :class:`_ParentGone` raised.
    """
    if not hasattr(os, "fork"):
        return run_spawned(fn, task, timeout)
    r, w = os.pipe()
    me = os.getpid()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        die_with_parent(me)
        os.close(r)
        faulthandler.disable()  # a crash is reported as the task's error row, not as a dump
        code = 0
        try:
            payload = pickle.dumps(("ok", fn(task)))
        except BaseException as exc:
            payload = pickle.dumps(("raised", describe_failure(exc),
                                    traceback.format_exc(limit=5)))  # fmt: skip
            code = 1
        try:
            view = memoryview(payload)
            while view:
                view = view[os.write(w, view) :]
        finally:
            os._exit(code)  # no atexit handlers, no nanobind leak reports, no flushing twice
    os.close(w)
    try:
        data = _read_all(r, timeout, watch.fileno() if watch is not None else None)
    except _ParentGone:
        _reap(pid, killed=True)
        raise
    status = _reap(pid, killed=data is None)
    if data:
        try:
            kind, *rest = pickle.loads(data)
        except Exception:  # a torn message: the child died while writing
            kind, rest = "torn", []
        if kind == "ok":
            return rest[0]
        if kind == "raised":
            return ChildFailure(f"the run raised {rest[0]}", detail=rest[1])
    if data is None:
        return ChildFailure(f"the run took longer than {timeout:.0f} s and was stopped")
    return ChildFailure(f"the run's process died ({status})")


class ChildFailure:
    """How a child run failed (it becomes the task's error row)."""

    def __init__(self, message: str, detail: str = "") -> None:
        self.message = message
        self.detail = detail

    def __repr__(self) -> str:
        return f"ChildFailure({self.message!r})"


def _read_all(fd: int, timeout: float, watch: int | None = None) -> bytes | None:
    """Everything written to the pipe until the writer closes it; None on timeout.

    Raises :class:`_ParentGone` when the file descriptor ``watch`` becomes readable first."""
    chunks = []
    deadline = time.monotonic() + timeout
    fds = [fd] if watch is None else [fd, watch]
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select(fds, [], [], left)
            if not ready:
                return None
            if watch in ready:
                raise _ParentGone
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)
    finally:
        os.close(fd)


def _reap(pid: int, killed: bool) -> str:
    """Wait for the child (killing it first when it overran); how it ended, in words."""
    if killed:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        try:
            name = signal.Signals(sig).name
        except ValueError:
            name = str(sig)
        return f"killed by signal {name}"
    return f"exit status {os.WEXITSTATUS(status)}"


#: What a fork server imports once, so that the processes it forks start planning at once (the
#: warm workers' imports; importing OMPL creates none of its objects, so its seed is still free).
WARM_MODULES = ("numpy", "scipy.sparse.csgraph", "shapely", "ompl.base", "ompl.geometric",
                "rrtpso_ompl.planners", "rrtpso_ompl.harness.batch")  # fmt: skip


def _forkserver() -> Any:
    """The fork-server context, preloaded with :data:`WARM_MODULES` (one server per process)."""
    ctx = mp.get_context("forkserver")
    ctx.set_forkserver_preload(list(WARM_MODULES))
    return ctx


_DAEMON_LOCK = threading.Lock()
_daemon_users = 0
_daemon_saved: Any = None


@contextlib.contextmanager
def _children_allowed() -> Iterator[None]:
    """Let a daemonic process (a Dask worker is one) start the run's process.

    multiprocessing refuses children to daemonic processes, so that none outlives its parent
    unnoticed; the run's process is waited for (with a timeout) before this returns, so none
    does. The flag is multiprocessing's own (``_config["daemon"]``; there is no public way to
    say this), cleared while any thread of this process starts runs and restored after."""
    global _daemon_users, _daemon_saved
    config = mp.current_process()._config
    with _DAEMON_LOCK:
        if _daemon_users == 0:
            _daemon_saved = config.get("daemon")
            config["daemon"] = False
        _daemon_users += 1
    try:
        yield
    finally:
        with _DAEMON_LOCK:
            _daemon_users -= 1
            if _daemon_users == 0 and _daemon_saved is not None:
                config["daemon"] = _daemon_saved


def run_spawned(fn: Callable[[Any], Any], task: Any, timeout: float, warm: bool = False) -> Any:
    """``fn(task)`` in a process of its own; ``warm`` forks it from a fork server that has
    imported :data:`WARM_MODULES` (milliseconds instead of half a second of imports, and safe
    from a threaded parent such as a Dask worker, since the server itself runs no threads).

    The run's process ends when this process does, whatever kills it (:func:`_watched_call`)."""
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    warm = warm and "forkserver" in mp.get_all_start_methods()
    ctx = _forkserver() if warm else mp.get_context("spawn")
    with _children_allowed(), ProcessPoolExecutor(1, mp_context=ctx) as pool:
        try:
            return pool.submit(_watched_call, fn, task, os.getpid()).result(timeout=timeout)
        except BrokenProcessPool:
            return ChildFailure("the run's process died")
        except Exception as exc:
            return ChildFailure(f"the run raised {describe_failure(exc)}")


def _watched_call(fn: Callable[[Any], Any], task: Any, owner: int) -> Any:
    """``fn(task)`` in a process that ends as soon as the process ``owner`` does.

    The process :func:`run_spawned` starts is a child of the fork server (or of the pool), not of
    ``owner``, so the kernel's parent-death signal cannot tie the two: a thread waits for
    ``owner`` to end instead (this process never forks, so the thread is safe)."""
    threading.Thread(target=_exit_when_gone, args=(owner,), daemon=True).start()
    return fn(task)


def _exit_when_gone(pid: int) -> None:
    """Wait until the process ``pid`` ends (a pidfd where the platform has one, else polling
    twice a second), then end this process at once."""
    try:
        fd = os.pidfd_open(pid)
    except (AttributeError, OSError):  # not Linux >= 5.3, or already gone
        fd = None
    if fd is not None:
        select.select([fd], [], [])
    else:
        while True:
            try:
                os.kill(pid, 0)
            except (ProcessLookupError, PermissionError):  # gone (or its pid another user's)
                break
            time.sleep(0.5)
    os._exit(1)


# ----------------------------------------------------------------------------------------------
# The local pool of warm workers
# ----------------------------------------------------------------------------------------------
def _worker_main(conn: Connection, fn: Callable[[Any], Any], warm: Callable[[], None] | None,
                 prepare: Callable[[Any], None] | None,
                 timeout_of: Callable[[Any], float], parent: int) -> None:  # fmt: skip
    """A warm worker: imports once, then runs each task it receives in a forked child, after
    ``prepare(task)`` (loading its problem, which the following runs of it share). It ends with
    its parent ``parent`` (a pid), whatever kills that."""
    die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
    if hasattr(os, "setpgrp"):
        os.setpgrp()  # the worker and its children: one group the parent can stop at once
    if warm is not None:
        warm()
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        index, task = message
        if prepare is not None:
            with contextlib.suppress(Exception):
                prepare(task)
        try:
            result = run_once_in_child(fn, task, timeout_of(task), watch=conn)
        except _ParentGone:
            return
        try:
            conn.send((index, result))
        except OSError:  # the parent is gone (a closed pipe): so are we, without a traceback
            return


class _Worker:
    def __init__(self, ctx: Any, fn, warm, prepare, timeout_of) -> None:
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_worker_main,
                                   args=(child, fn, warm, prepare, timeout_of, os.getpid()),
                                   daemon=True)  # fmt: skip
        self.process.start()
        child.close()
        self.busy: tuple[int, Any] | None = None

    def give(self, index: int, task: Any) -> None:
        self.busy = (index, task)
        self.conn.send((index, task))

    def stop(self, force: bool) -> None:
        if force:
            self._kill()
        else:
            with contextlib.suppress(OSError):
                self.conn.send(None)
        self.process.join(timeout=5)
        if self.process.is_alive():
            self._kill()
        self.process.join()

    def _kill(self) -> None:
        """Kill the worker and the child it may be running (its process group)."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except (AttributeError, ProcessLookupError, PermissionError):
            self.process.kill()


def run_local(
    tasks: Iterable[Any],
    fn: Callable[[Any], Any],
    jobs: int,
    *,
    warm: Callable[[], None] | None = None,
    prepare: Callable[[Any], None] | None = None,
    timeout_of: Callable[[Any], float],
) -> Iterator[tuple[Any, Any]]:
    """Run ``fn(task)`` for every task on ``jobs`` warm workers; yields ``(task, result)`` as they
    finish, where ``result`` is ``fn``'s value or a :class:`ChildFailure`.

    ``warm()`` runs once in each worker (imports), ``prepare(task)`` in the worker before each
    fork (what the runs of a task can share); ``timeout_of(task)`` bounds each run. Closing
    the iterator early (or Ctrl-C in the parent) stops the workers and their children.
    """
    ctx = mp.get_context("spawn")
    queue = list(enumerate(tasks))[::-1]
    workers = [
        _Worker(ctx, fn, warm, prepare, timeout_of) for _ in range(max(1, min(jobs, len(queue))))
    ]
    clean = False
    try:
        for w in workers:
            if queue:
                w.give(*queue.pop())
        while any(w.busy is not None for w in workers):
            ready = wait([w.conn for w in workers if w.busy] +
                         [w.process.sentinel for w in workers if w.busy])  # fmt: skip
            for i, w in enumerate(workers):
                if w.busy is None:
                    continue
                _, task = w.busy
                result = None
                if w.conn in ready:
                    try:
                        _, result = w.conn.recv()
                        w.busy = None
                    except (EOFError, OSError):
                        pass  # the worker died: its pipe closed (the sentinel follows)
                if w.busy is not None and (w.conn in ready or w.process.sentinel in ready):
                    # The worker itself died: its task is lost; replace the worker.
                    w.process.join(timeout=5)
                    result = ChildFailure(f"the worker process died (exit code "
                                          f"{w.process.exitcode})")  # fmt: skip
                    w.conn.close()
                    workers[i] = w = _Worker(ctx, fn, warm, prepare, timeout_of)
                elif result is None and w.busy is not None:
                    continue
                if queue:
                    w.give(*queue.pop())
                yield task, result
        clean = True
    finally:
        for w in workers:
            w.stop(force=not clean)
