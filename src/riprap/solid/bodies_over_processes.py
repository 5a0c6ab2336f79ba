"""Rigid bodies split over processes by the place of their centre.

Each process owns the bodies whose centre lies in its slab of x (``cuts``), and does for them
what grows with the contacts: it finds their candidate pairs among the bodies near its slab only
(``owned_step.local_candidates``), evaluates each pair whose first body it owns (once in the
run: the pair's other body, when another process owns it, gets the pair's row of results in a
message), and adds up its own bodies' forces; the processes then join their bodies' forces and
torques (6 numbers a body), and every process integrates every body alike, so each holds a copy
of every body for the next broad phase and for the fluid. A body crossing a cut is owned by the
next process from the next step: nothing of it moves but its contacts' springs, which the
processes join on a step where any body changed owner.

Bit for bit: the pairs are listed in (i, j) order on one process as on each of many, so every
body's forces are added in the same order; the joined forces are each one process's sum.

A periodic direction (``SolidSolver.set_periodic``) changes nothing here: every process wraps the
centres and takes the pairs by minimum image as one process does; with x periodic the first and
last slabs are neighbours through the strip's ends (``owned_step.local_candidates``).

Why the slabs of the contacts are not the fluid's: the slabs are cut afresh at each ``advance``
(a fluid step) so that each holds about the same number of pairs (each body weighted by the
pairs it was first in at the last evaluation), since the fluid's cut balances the cells, and an
armour layer's bodies lie in a few of its slabs. Re-cutting moves nothing: at the start of each
``advance`` every process holds every spring.
"""
from __future__ import annotations

import time

import numpy as np

from riprap.solid.kernels import interactions, owned_step, stepper

__all__ = ["BodiesOverProcesses"]

#: the cuts are kept while no process has more than this times the mean work
_KEEP_CUTS_WITHIN = 1.03
_BODY_ROW = 0.0
_WALL_ROW = 1.0


class BodiesOverProcesses:
    """Steps a ``SolidSolver``'s bodies with their contact work split over ``processes``."""

    def __init__(self, processes):
        self.processes = processes
        #: the x of the cuts of the last ``advance`` (m), (processes - 1,)
        self.cuts = np.zeros(0)
        #: the steps of the last ``advance`` at which a body changed owner
        self.owner_changes = 0
        #: seconds spent, summed over the run, in each part of the step (bench/parallel.py):
        #: integrating every body, the broad phase, the pairs, the messages (waiting included),
        #: the sums of the forces
        self.seconds = dict.fromkeys(("integration", "broad_phase", "pairs", "messages", "sums"),
                                     0.0)
        #: each process's seconds per unit of bodies' weight, relative (``balanced_cuts``)
        self.pace = np.ones(processes.size)
        self._weights = np.zeros(0)

    # ------------------------------------------------------------------ the slabs
    def balanced_cuts(self, solver) -> np.ndarray:
        """Cuts in x that give each process about the same work: a body weighs one plus the
        candidate pairs it was first in at the last force evaluation, times the seconds a unit
        of weight took on the process that owned it over the last ``advance`` (``pace``: pairs
        differ in cost, a Core-Loc pair's narrow phase against a rock's, a touching pair's
        against a near one's). The cut changes no result, only who does the work."""
        size = self.processes.size
        _, body_pairs, wall_pairs = solver._last
        n = len(solver.positions)
        weights = 1.0 + np.bincount(np.concatenate([body_pairs[:, 0], wall_pairs[:, 0]]),
                                    minlength=n)
        x = solver.positions[:, 0]
        self._weights = weights
        if len(self.cuts) == size - 1:
            owners = owned_step.owners_of(solver.positions, self.cuts)
            weights = weights * self.pace[owners]
            loads = np.bincount(owners, weights=weights, minlength=size)
            if loads.max() <= _KEEP_CUTS_WITHIN * loads.mean():
                # a cut that moves hands pairs to another process, whose surface pieces it
                # must list afresh: keep the cuts while they stay balanced
                return self.cuts
        order = np.argsort(x, kind="stable")
        x, running = x[order], np.cumsum(weights[order])
        cuts = np.full(size - 1, np.inf)
        if n > 1:
            for p in range(1, size):
                k = int(np.searchsorted(running, running[-1] * p / size))
                k = min(max(k, 1), n - 1)
                cuts[p - 1] = 0.5 * (x[k - 1] + x[k])
        return np.maximum.accumulate(cuts)

    def _measure_pace(self, owners, pair_seconds: float) -> None:
        """``pace`` from this ``advance``: each process's seconds in its pairs over the weight of
        the bodies it owned (one message), blended half and half with the last."""
        mine = float(self._weights[owners == self.processes.rank].sum())
        every = np.array(self.processes.all_values((pair_seconds, mine)), dtype=np.float64)
        seconds, weight = every[:, 0], every[:, 1]
        if (seconds > 0.0).all() and (weight > 0.0).all():
            pace = seconds / weight
            pace /= pace.mean()
            self.pace = 0.5 * self.pace + 0.5 * pace

    def slab_of(self, rank: int) -> tuple[float, float]:
        lower = -np.inf if rank == 0 else float(self.cuts[rank - 1])
        upper = np.inf if rank == self.processes.size - 1 else float(self.cuts[rank])
        return lower, upper

    def owned_counts(self, solver) -> list[int]:
        """The bodies each process owns at the bodies' present places."""
        owners = owned_step.owners_of(solver.positions, self.cuts)
        return np.bincount(owners, minlength=self.processes.size).tolist()

    # ------------------------------------------------------------------ the step
    def advance(self, solver, n_steps: int) -> tuple[int, int]:
        """``n_steps`` velocity-Verlet steps of ``solver`` (a ``SolidSolver``); returns (the
        steps done, the status of ``stepper``: the state is left at the failing step, as on one
        process)."""
        rank = self.processes.rank
        self.cuts = self.balanced_cuts(solver)
        lower, upper = self.slab_of(rank)
        system, motion, history, settings = solver._kernel_state(solver.time_step)
        positions, forces, torques = motion[0], motion[4], motion[5]
        omegas, cache = solver._omegas, solver._piece_cache
        owners = None
        self.owner_changes = 0
        status, done = stepper.STATUS_OK, 0
        key_stride = len(positions) + len(solver.wall_points)
        body_pairs = np.zeros((0, 2), np.int64)
        wall_pairs = np.zeros((0, 2), np.int64)
        mine = np.zeros(0, bool)
        own_rows = np.zeros((0, interactions.C_SIZE))
        clock = self.seconds
        pairs_before = clock["pairs"]
        for step in range(n_steps):
            started = time.perf_counter()
            owned_step.first_half(system, motion, omegas, settings)
            now = owned_step.owners_of(positions, self.cuts)
            if owners is not None and not np.array_equal(now, owners):
                self.owner_changes += 1
                history = self._joined_history(history, owners, key_stride)
            owners = now
            t1 = time.perf_counter()
            body_pairs, wall_pairs, omegas, key_stride = owned_step.local_candidates(
                system, motion, settings, owners, rank, lower, upper)
            first_owner = owners[body_pairs[:, 0]]
            second_owner = owners[body_pairs[:, 1]]
            mine = first_owner == rank
            t2 = time.perf_counter()
            own_rows, cache = interactions.evaluate_candidates(
                body_pairs[mine], wall_pairs, system, motion, omegas, history, settings, cache)
            t3 = time.perf_counter()
            results = self._with_rows_of_others(own_rows, mine, first_owner, second_owner,
                                                len(wall_pairs))
            t4 = time.perf_counter()
            history, overflow = stepper.forces_of_contacts(
                system, motion, settings, body_pairs, wall_pairs, results, key_stride)
            t5 = time.perf_counter()
            joined_forces, joined_torques, overflow = self._joined_forces(
                forces, torques, owners, overflow)
            t6 = time.perf_counter()
            finite = owned_step.second_half(system, motion, omegas, settings, joined_forces,
                                            joined_torques)
            ended = time.perf_counter()
            clock["integration"] += t1 - started + ended - t6
            clock["broad_phase"] += t2 - t1
            clock["pairs"] += t3 - t2
            clock["messages"] += t4 - t3 + t6 - t5
            clock["sums"] += t5 - t4
            done = step + 1
            if overflow:
                status = stepper.STATUS_OVERFLOW
                break
            if not finite:
                status = stepper.STATUS_NOT_FINITE
                break
        if owners is not None:
            self._measure_pace(owners, clock["pairs"] - pairs_before)
            history = self._joined_history(history, owners, key_stride)
            solver._store_results(*self._joined_results(own_rows, body_pairs[mine], wall_pairs,
                                                        key_stride, len(solver.wall_points)))
        solver._omegas, solver._piece_cache = omegas, cache
        solver.history_keys, solver.history_springs = history
        return done, status

    def _with_rows_of_others(self, own_rows, mine, first_owner, second_owner, n_walls):
        """This process's list of results (its body pairs, then its body-wall pairs): the rows it
        evaluated, and those of pairs whose first body another process owns, received from it.
        The rows go in the pairs' (i, j) order within each message, the order both ends list
        them in."""
        processes, rank = self.processes, self.processes.rank
        n_mine = int(mine.sum())
        sent = second_owner[mine] != rank
        destinations = second_owner[mine][sent]
        order = np.argsort(destinations, kind="stable")
        theirs = np.flatnonzero(~mine)
        sources = first_owner[theirs]
        received = processes.exchange_rows(
            own_rows[:n_mine][sent][order], np.bincount(destinations, minlength=processes.size),
            np.bincount(sources, minlength=processes.size))
        results = np.empty((len(mine) + n_walls, interactions.C_SIZE))
        results[:len(mine)][mine] = own_rows[:n_mine]
        results[theirs[np.argsort(sources, kind="stable")]] = received
        results[len(mine):] = own_rows[n_mine:]
        return results

    def _joined_forces(self, forces, torques, owners, overflow):
        """Every body's force and torque, each from the process that owns it, and whether any
        process's contact buffers overflowed (one message)."""
        processes = self.processes
        own = np.flatnonzero(owners == processes.rank)
        rows = np.empty((len(own) + 1, 6))
        rows[:-1, :3] = forces[own]
        rows[:-1, 3:] = torques[own]
        rows[-1] = float(overflow)
        counts = np.bincount(owners, minlength=processes.size) + 1
        joined = processes.join_rows(rows, counts)
        flags = np.cumsum(counts) - 1
        overflow = bool(joined[flags, 0].any())
        joined = np.delete(joined, flags, axis=0)
        every = np.empty((len(owners), 6))
        every[np.argsort(owners, kind="stable")] = joined
        return np.ascontiguousarray(every[:, :3]), np.ascontiguousarray(every[:, 3:]), overflow

    def _joined_history(self, history, owners, key_stride):
        """The springs of every contact, in key order: each process gives those of the pairs it
        evaluated (whose first body it owned)."""
        keys, springs = history
        own = owners[keys // key_stride] == self.processes.rank
        rows = np.empty((int(own.sum()), 1 + springs.shape[1]))
        rows[:, 0] = keys[own]    # keys < 2**53: exact as doubles
        rows[:, 1:] = springs[own]
        joined = self.processes.join_rows(rows, self.processes.all_values(len(rows)))
        order = np.argsort(joined[:, 0], kind="stable")
        joined = joined[order]
        return type(history)(joined[:, 0].astype(np.int64), np.ascontiguousarray(joined[:, 1:]))

    def _joined_results(self, own_rows, own_pairs, own_walls, key_stride, n_walls):
        """The last force evaluation's rows of every process, in one process's order (body pairs
        by (i, j), then body-wall pairs by body and wall), for the contact records."""
        width = interactions.C_SIZE
        rows = np.empty((len(own_rows), 3 + width))
        n_pairs = len(own_pairs)
        rows[:n_pairs, 0] = _BODY_ROW
        rows[n_pairs:, 0] = _WALL_ROW
        rows[:n_pairs, 1:3] = own_pairs
        rows[n_pairs:, 1:3] = own_walls
        rows[:, 3:] = own_rows
        joined = self.processes.join_rows(rows, self.processes.all_values(len(rows)))
        pairs = joined[:, 1:3].astype(np.int64)
        body = joined[:, 0] == _BODY_ROW
        body_order = np.argsort(pairs[body, 0] * key_stride + pairs[body, 1], kind="stable")
        wall_order = np.argsort(pairs[~body, 0] * max(n_walls, 1) + pairs[~body, 1], kind="stable")
        results = np.concatenate([joined[body][body_order, 3:], joined[~body][wall_order, 3:]])
        return (np.ascontiguousarray(results), np.ascontiguousarray(pairs[body][body_order]),
                np.ascontiguousarray(pairs[~body][wall_order]))
