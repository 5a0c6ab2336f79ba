"""The processes of one run and what they say to each other.

Why a class of our own over mpi4py: every solver asks for the same few things (a largest value, a
sum in the one order a single process would add it, the planes next to its slab from its
neighbours, a whole coarse grid gathered), and a run on one process must not need MPI at all. So
``SingleProcess`` answers them for one process without importing mpi4py, and ``MpiProcesses``
answers them over MPI. ``world()`` picks one: MPI only when a launcher (``mpiexec``, ``srun``)
started more than one process.

Sums in order: the fluid's reductions are formed per x-plane and the planes added in x order
(``riprap/fluid/kernels/multigrid.py``). Every slab is a run of whole x-planes, so gathering the
planes' partial sums in rank order and adding them one by one gives the single process's sum bit
for bit (``ordered_sum``).
"""
from __future__ import annotations

import os
import time

import numpy as np

from riprap.errors import RiprapError
from riprap.parallel.kernels.ordered import ordered_total

__all__ = ["SingleProcess", "MpiProcesses", "world", "launched_processes", "ParallelError"]

# The variables a launcher sets to the number of processes it started: MPICH and Intel MPI
# (PMI_SIZE), Open MPI (OMPI_COMM_WORLD_SIZE), PMIx launchers (PMIX_SIZE is not standard; Open
# MPI 5 sets OMPI_COMM_WORLD_SIZE too), Slurm's srun with --mpi (PMI_SIZE).
#: Seconds an aborting process waits for the launcher to read what it wrote (``abort``).
_ABORT_GRACE_SECONDS = 0.5

_LAUNCHER_SIZE_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "MPI_LOCALNRANKS")


class ParallelError(RiprapError):
    """A run over several processes cannot start or went wrong on one of them."""


def launched_processes() -> int:
    """How many processes the launcher started (1 when no launcher did)."""
    for name in _LAUNCHER_SIZE_VARIABLES:
        value = os.environ.get(name)
        if value and value.isdigit():
            return max(1, int(value))
    return 1


class SingleProcess:
    """One process: every reduction is the value itself."""

    rank = 0
    size = 1
    name = "one process"

    def max(self, value: float) -> float:
        return float(value)

    def sum_int(self, value: int) -> int:
        return int(value)

    def any(self, flag: bool) -> bool:
        return bool(flag)

    def ordered_rows(self, rows: np.ndarray, counts) -> np.ndarray:
        return np.ascontiguousarray(rows)

    def ordered_sum(self, rows: np.ndarray, counts) -> float:
        return float(ordered_total(np.ascontiguousarray(rows, dtype=np.float64)))

    def gather_planes(self, local: np.ndarray, counts) -> np.ndarray:
        return local

    def gather_planes_on_first(self, local: np.ndarray, counts):
        return local

    def sum_arrays(self, values: np.ndarray) -> np.ndarray:
        return np.array(values, dtype=np.float64)

    def join_rows(self, rows: np.ndarray, counts) -> np.ndarray:
        return np.array(rows, dtype=np.float64)

    def exchange_rows(self, rows: np.ndarray, send_counts, receive_counts) -> np.ndarray:
        return np.array(rows, dtype=np.float64)

    def swap_planes(self, to_low, to_high, n_from_low: int, n_from_high: int):
        return None, None

    def exchange(self, array: np.ndarray, send_low, receive_low, send_high, receive_high) -> None:
        return None

    def broadcast(self, value):
        return value

    def all_values(self, value) -> list:
        return [value]

    def barrier(self) -> None:
        return None

    def abort(self, code: int = 1) -> None:
        raise SystemExit(code)


class MpiProcesses:
    """Processes of an MPI communicator (``mpi4py``); the slabs are ordered by rank."""

    def __init__(self, comm):
        from mpi4py import MPI  # lazy: only runs over several processes import MPI
        self._mpi = MPI
        self.comm = comm
        self.rank = comm.Get_rank()
        self.size = comm.Get_size()
        self.name = f"process {self.rank} of {self.size}"
        self._low = self.rank - 1 if self.rank > 0 else MPI.PROC_NULL
        self._high = self.rank + 1 if self.rank < self.size - 1 else MPI.PROC_NULL
        #: What this process sent and how long it waited, per kind (``traffic``): halo and ghost
        #: exchanges with the neighbours, reductions and gathers over all processes.
        self.traffic = {kind: {"messages": 0, "bytes": 0, "seconds": 0.0}
                        for kind in ("exchange", "reduction", "gather")}

    def _count(self, kind: str, started: float, sent_bytes: int, messages: int = 1) -> None:
        entry = self.traffic[kind]
        entry["messages"] += messages
        entry["bytes"] += int(sent_bytes)
        entry["seconds"] += time.perf_counter() - started

    def max(self, value: float) -> float:
        started = time.perf_counter()
        result = float(self.comm.allreduce(float(value), op=self._mpi.MAX))
        self._count("reduction", started, 8)
        return result

    def sum_int(self, value: int) -> int:
        started = time.perf_counter()
        result = int(self.comm.allreduce(int(value), op=self._mpi.SUM))
        self._count("reduction", started, 8)
        return result

    def any(self, flag: bool) -> bool:
        started = time.perf_counter()
        result = bool(self.comm.allreduce(bool(flag), op=self._mpi.LOR))
        self._count("reduction", started, 1)
        return result

    def ordered_rows(self, rows: np.ndarray, counts) -> np.ndarray:
        """Every process's ``rows`` (its planes' values, (n, ...) with n = counts[rank]) joined
        in rank order, on every process."""
        started = time.perf_counter()
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        per_row = int(np.prod(rows.shape[1:], dtype=np.int64))
        counts = np.asarray(counts, dtype=np.int64) * per_row
        out = np.empty((int(counts.sum() // max(per_row, 1)),) + rows.shape[1:])
        displacements = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self.comm.Allgatherv(rows, [out, counts, displacements, self._mpi.DOUBLE])
        # a few numbers per plane are a reduction; whole planes of a grid are a gather
        self._count("reduction" if per_row <= 3 else "gather", started, rows.nbytes)
        return out

    def ordered_sum(self, rows: np.ndarray, counts) -> float:
        """The sum of every process's per-plane partial sums, added in plane order from 0.0: what
        one process adding all planes gets, bit for bit."""
        return float(ordered_total(self.ordered_rows(rows, counts)))

    def gather_planes(self, local: np.ndarray, counts) -> np.ndarray:
        """The whole array from every process's planes (axis 0), on every process."""
        return self.ordered_rows(local, counts)

    def gather_planes_on_first(self, local: np.ndarray, counts):
        """The whole array from every process's planes (axis 0) on process 0 (the writer of
        the run's tables and pictures); None on the others, which then hold no whole-grid
        array."""
        started = time.perf_counter()
        local = np.ascontiguousarray(local, dtype=np.float64)
        per_row = int(np.prod(local.shape[1:], dtype=np.int64))
        counts = np.asarray(counts, dtype=np.int64) * per_row
        out = None
        receive = None
        if self.rank == 0:
            out = np.empty((int(counts.sum() // max(per_row, 1)),) + local.shape[1:])
            displacements = np.concatenate([[0], np.cumsum(counts)[:-1]])
            receive = [out, counts, displacements, self._mpi.DOUBLE]
        self.comm.Gatherv(local, receive, root=0)
        self._count("gather", started, local.nbytes)
        return out

    def sum_arrays(self, values: np.ndarray) -> np.ndarray:
        """Every process's ``values`` (the same shape on all) added element by element in rank
        order, the same bits on every process (an MPI sum's order may differ between
        processes; this one's does not)."""
        started = time.perf_counter()
        values = np.ascontiguousarray(values, dtype=np.float64)
        every = np.empty((self.size,) + values.shape)
        self.comm.Allgather(values, every)
        total = every[0].copy()
        for rank in range(1, self.size):
            total += every[rank]
        self._count("reduction", started, values.nbytes)
        return total

    def join_rows(self, rows: np.ndarray, counts) -> np.ndarray:
        """Every process's ``rows`` (counts[p], ...) one after the other in rank order, on every
        process."""
        started = time.perf_counter()
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        per_row = int(np.prod(rows.shape[1:], dtype=np.int64))
        counts = np.asarray(counts, dtype=np.int64) * per_row
        out = np.empty((int(counts.sum()) // max(per_row, 1),) + rows.shape[1:])
        displacements = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self.comm.Allgatherv(rows, [out, counts, displacements, self._mpi.DOUBLE])
        self._count("reduction", started, rows.nbytes)
        return out

    def exchange_rows(self, rows: np.ndarray, send_counts, receive_counts) -> np.ndarray:
        """Rows to each process and from each (``rows`` grouped by destination in rank order,
        ``send_counts[p]`` of them for process p; ``receive_counts[p]`` come from process p):
        the rows received, grouped by source in rank order."""
        started = time.perf_counter()
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        per_row = int(np.prod(rows.shape[1:], dtype=np.int64))
        sent = np.asarray(send_counts, dtype=np.int64) * per_row
        taken = np.asarray(receive_counts, dtype=np.int64) * per_row
        out = np.empty((int(taken.sum()) // max(per_row, 1),) + rows.shape[1:])
        self.comm.Alltoallv(
            [rows, sent, np.concatenate([[0], np.cumsum(sent)[:-1]]), self._mpi.DOUBLE],
            [out, taken, np.concatenate([[0], np.cumsum(taken)[:-1]]), self._mpi.DOUBLE])
        self._count("exchange", started, rows.nbytes)
        return out

    def swap_planes(self, to_low: np.ndarray, to_high: np.ndarray, n_from_low: int,
                    n_from_high: int):
        """Planes (along axis 0) to the neighbouring slabs and from them: ``to_high`` to the
        next process, ``to_low`` to the previous; ``n_from_low`` planes of the same shape come
        from the previous, ``n_from_high`` from the next. Returns (from the previous, from the
        next), None where there is no neighbour."""
        mpi = self._mpi
        started = time.perf_counter()
        plane = to_low.shape[1:]
        from_low = np.empty((n_from_low,) + plane) if self._low != mpi.PROC_NULL else None
        from_high = np.empty((n_from_high,) + plane) if self._high != mpi.PROC_NULL else None
        self.comm.Sendrecv(np.ascontiguousarray(to_high, dtype=np.float64), dest=self._high,
                           sendtag=3, recvbuf=from_low if from_low is not None else np.empty(0),
                           source=self._low, recvtag=3)
        self.comm.Sendrecv(np.ascontiguousarray(to_low, dtype=np.float64), dest=self._low,
                           sendtag=4, recvbuf=from_high if from_high is not None else np.empty(0),
                           source=self._high, recvtag=4)
        sent = to_high.nbytes * (self._high != mpi.PROC_NULL) \
            + to_low.nbytes * (self._low != mpi.PROC_NULL)
        self._count("exchange", started, sent, 2)
        return from_low, from_high

    def exchange(self, array: np.ndarray, send_low, receive_low, send_high, receive_high) -> None:
        """Planes of ``array`` along axis 0 to and from the neighbouring slabs: ``send_high``
        (a slice) goes to the next process's ``receive_low``, ``send_low`` to the previous
        one's ``receive_high``. Slices of a C-ordered array along axis 0 are contiguous, so no
        copy is made."""
        mpi = self._mpi
        started = time.perf_counter()
        receive = np.empty_like(array[receive_low]) if self._low != mpi.PROC_NULL else None
        self.comm.Sendrecv(np.ascontiguousarray(array[send_high]), dest=self._high, sendtag=1,
                           recvbuf=receive if receive is not None else np.empty(0),
                           source=self._low, recvtag=1)
        if receive is not None:
            array[receive_low] = receive
        receive = np.empty_like(array[receive_high]) if self._high != mpi.PROC_NULL else None
        self.comm.Sendrecv(np.ascontiguousarray(array[send_low]), dest=self._low, sendtag=2,
                           recvbuf=receive if receive is not None else np.empty(0),
                           source=self._high, recvtag=2)
        if receive is not None:
            array[receive_high] = receive
        sent = array[send_high].nbytes * (self._high != mpi.PROC_NULL) \
            + array[send_low].nbytes * (self._low != mpi.PROC_NULL)
        self._count("exchange", started, sent,
                    int(self._high != mpi.PROC_NULL) + int(self._low != mpi.PROC_NULL))

    def broadcast(self, value):
        return self.comm.bcast(value, root=0)

    def all_values(self, value) -> list:
        started = time.perf_counter()
        result = self.comm.allgather(value)
        self._count("reduction", started, 64)
        return result

    def barrier(self) -> None:
        self.comm.Barrier()

    def abort(self, code: int = 1) -> None:
        """End every process of the run. The launcher forwards each process's output as it
        reads it, and an abort tears the pipes down at once: a message written just before could
        be lost (seen: a refusal that every process met, each aborting, and none of its lines
        reached the terminal). So the output is flushed and given a moment to be read first."""
        import sys
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        time.sleep(_ABORT_GRACE_SECONDS)
        self.comm.Abort(code)


_WORLD = None


def world():
    """The processes of this run: ``MpiProcesses`` when a launcher started more than one (mpi4py
    needed), else ``SingleProcess``. The same object on every call."""
    global _WORLD
    if _WORLD is not None:
        return _WORLD
    launched = launched_processes()
    if launched <= 1:
        _WORLD = SingleProcess()
        return _WORLD
    try:
        from mpi4py import MPI  # lazy: a run on one process never initialises MPI
    except ImportError as error:
        raise ParallelError(
            f"riprap was started as {launched} processes, but mpi4py is not installed, so they "
            "cannot work as one run: install it with `python3 -m pip install '.[mpi]'` in "
            "riprap's folder (mpi4py and the MPICH wheel; or `python3 -m pip install mpi4py` "
            "for your cluster's MPI), or run one process without mpiexec") from error
    comm = MPI.COMM_WORLD
    if comm.Get_size() == 1:
        _WORLD = SingleProcess()
    else:
        _WORLD = MpiProcesses(comm)
        _end_all_on_uncaught_error(_WORLD)
    return _WORLD


def _end_all_on_uncaught_error(processes: MpiProcesses) -> None:
    """An error that escapes on one process ends every process of the run at once, with one
    message naming the process: the others would otherwise wait for it in their next exchange
    for ever. (Errors the run loop handles, such as an instability, are met by every process
    together and end the run in order, with a checkpoint.)"""
    import sys
    import traceback

    def end_all(kind, error, trace):
        text = "".join(traceback.format_exception(kind, error, trace))
        sys.stderr.write(f"riprap: {processes.name} failed; ending every process of the run.\n"
                         f"{text}")
        sys.stderr.flush()
        processes.abort(1)

    sys.excepthook = end_all
