"""Telemetry of a simulation run: one row per control period (robots) or step (mechanisms),
saved as ``.npz``."""

from __future__ import annotations

import os
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Generic, TypeVar

import numpy as np

from ..errors import TelemetryFileError

A = TypeVar("A", bound="Arrays")


class Arrays:
    """Dataclass of equally long arrays (one row per sample): truncation and ``.npz`` I/O."""

    def truncated(self: A, rows: int) -> A:
        """The first ``rows`` samples (what a run had when it stopped)."""
        return self.window(0, rows)

    def window(self: A, start: int, stop: int) -> A:
        """Samples ``start`` to ``stop - 1``, as views of these arrays (not copies)."""
        return type(self)(**{f.name: getattr(self, f.name)[start:stop] for f in fields(self)})

    def copied(self: A) -> A:
        """The same samples in arrays of their own."""
        return type(self)(**{f.name: getattr(self, f.name).copy() for f in fields(self)})

    def save(self, path: str | Path, *, compressed: bool = True, **metadata: object) -> None:
        """Write all arrays to ``path`` (.npz); ``metadata`` values are stored as arrays too.
        ``compressed``: deflated at zlib's fastest level (``numpy.load`` reads either; on the
        default job's telemetry level 1 took 0.62x level 6's time for a 2 % larger file, and not
        compressing 0.03x its time for twice the size: checkpoints, which a finished run removes).

        The file is written under a temporary name and renamed into place, so ``path`` is never
        a half-written file, whatever stops the process; the temporary file is opened without
        following a symbolic link. The archive is numpy's ``savez_compressed`` format, written
        here so that an archive an interrupt cut short is given up with its file (numpy's was
        closed again when garbage-collected, after its file, and Python printed 'Exception
        ignored ... ValueError: seek of closed file' after a clean Ctrl-C)."""
        path = Path(path)
        arrays = {f.name: getattr(self, f.name) for f in fields(self)}
        arrays.update({f"meta_{k}": np.asarray(v) for k, v in metadata.items()})
        partial = path.with_name(f".{path.name}.partial")
        fd = os.open(partial, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        with os.fdopen(fd, "wb") as file:
            archive = zipfile.ZipFile(file, "w", zipfile.ZIP_DEFLATED if compressed else zipfile.ZIP_STORED,
                                      compresslevel=1 if compressed else None, allowZip64=True)
            try:
                for name, array in arrays.items():
                    with archive.open(f"{name}.npy", "w", force_zip64=True) as member:
                        np.lib.format.write_array(member, np.asanyarray(array), allow_pickle=False)
                archive.close()
            finally:
                archive.fp = None  # closed, or given up with the file: never written to at garbage collection
        os.replace(partial, path)

    @classmethod
    def load(cls: type[A], path: str | Path) -> A:
        """Read a file written by :meth:`save` (metadata is ignored).

        Raises:
            TelemetryFileError: naming the file when it cannot be read, is not an ``.npz`` of
                this kind of telemetry (the arrays it lacks are listed) or its arrays differ in
                length.
        """
        names = [f.name for f in fields(cls)]
        try:
            data = np.load(path, allow_pickle=False)
            if not isinstance(data, np.lib.npyio.NpzFile):
                raise TelemetryFileError(f"'{path}' is a single array, not {cls.__name__} telemetry (.npz)")
            with data:
                missing = [n for n in names if n not in data.files]
                if missing:
                    raise TelemetryFileError(f"'{path}' is not {cls.__name__} telemetry: it lacks "
                                             f"{', '.join(missing)}")
                arrays = {n: data[n] for n in names}
        except TelemetryFileError:
            raise
        except FileNotFoundError:
            raise TelemetryFileError(f"'{path}' does not exist") from None
        except (OSError, ValueError, EOFError, KeyError, NotImplementedError, zipfile.BadZipFile, zlib.error) as exc:
            raise TelemetryFileError(f"'{path}' is damaged or not a telemetry file: {type(exc).__name__}: "
                                     f"{exc}") from None
        lengths = {n: len(a) if a.ndim else None for n, a in arrays.items()}
        if None in lengths.values() or len(set(lengths.values())) > 1:
            raise TelemetryFileError(f"'{path}' is damaged: its arrays differ in length "
                                     f"({', '.join(f'{n}: {k}' for n, k in lengths.items())})")
        return cls(**arrays)

    @classmethod
    def concatenate(cls: type[A], parts: list[A]) -> A:
        """The samples of ``parts``, in order, as one (parts must not be empty)."""
        return cls(**{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(cls)})

    @classmethod
    def load_parts(cls: type[A], folder: str | Path) -> A:
        """Every sample saved part by part in ``folder`` (``part-00000.npz``, ...; see
        :class:`Chunks`): what a run that was killed had checkpointed.

        Raises:
            FileNotFoundError: when ``folder`` holds no part.
            TelemetryFileError: naming the part that is damaged or foreign, or two parts whose
                columns do not match.
        """
        parts = sorted(Path(folder).glob("part-*.npz"))
        if not parts:
            raise FileNotFoundError(f"{folder}: no telemetry part (part-*.npz)")
        loaded = [cls.load(p) for p in parts]
        try:
            return cls.concatenate(loaded)
        except ValueError as exc:
            raise TelemetryFileError(f"'{folder}': its parts do not fit together ({exc})") from None


class Chunks(Generic[A]):
    """Samples recorded chunk by chunk instead of in one whole-run allocation: memory grows with
    what was recorded, and every full chunk is handed to ``on_chunk`` (e.g. saved to disk) as the
    run goes.

    The bookkeeping is two counters, each changed by one assignment: ``filled`` (rows written,
    over all chunks; row ``r`` lives in chunk ``r // rows``) and ``handed`` (chunks given to
    ``on_chunk``). An exception at any instruction (Ctrl-C, SIGTERM) therefore leaves a state
    where every row is either counted once or not at all, and a chunk whose hand-over was
    interrupted is handed again.

    Args:
        allocate: ``allocate(rows)``: an empty chunk of ``rows`` samples.
        rows: samples per chunk.
        on_chunk: called with each full chunk, in order (the same chunk again if the call before
            was interrupted).
    """

    def __init__(self, allocate: Callable[[int], A], rows: int = 1024,
                 on_chunk: Callable[[A], None] | None = None):
        self.allocate, self.rows, self.on_chunk = allocate, rows, on_chunk
        self.chunks: list[A] = []
        self.filled = 0
        self.handed = 0

    def next_row(self) -> tuple[A, int]:
        """The chunk and row index to write the next sample into; the row counts once
        :meth:`commit` says it is written (a sample interrupted half-way is not kept)."""
        k, row = divmod(self.filled, self.rows)
        self._hand_full(k)
        if k == len(self.chunks):
            self.chunks.append(self.allocate(self.rows))
        return self.chunks[k], row

    def _hand_full(self, k: int) -> None:
        """Hand chunks ``handed .. k - 1`` (full) to ``on_chunk``."""
        while self.handed < k:
            if self.on_chunk is not None:
                self.on_chunk(self.chunks[self.handed])
            self.handed += 1

    def commit(self, rows: int = 1) -> None:
        """Count the row :meth:`next_row` gave (and the ``rows - 1`` after it, filled in the same
        chunk) as written."""
        self.filled += rows

    def collect(self) -> A:
        """All samples recorded, in order; the full chunks not handed on yet and the last one
        (possibly partial) go to ``on_chunk`` too."""
        k, row = divmod(self.filled, self.rows)
        whole = self.chunks[:k]
        last = self.chunks[k].truncated(row) if row else None
        self._hand_full(k)
        if self.on_chunk is not None and last is not None:
            self.on_chunk(last)
        if not whole and last is None:
            return self.allocate(0)
        return type(whole[0] if whole else last).concatenate([*whole, *([last] if last is not None else [])])


@dataclass
class Telemetry(Arrays):
    """Recorded run. Row ``k`` is the state at time ``t[k]``; ``tau[k]`` is held over [t_k, t_k+1).

    Attributes:
        t: time, s (N,).
        q: Pinocchio configuration (N, nq); free-flyer base as [x, y, z, qx, qy, qz, qw] of the
            base-link frame, planar base as [x, y, cos yaw, sin yaw].
        v: Pinocchio velocity (N, nv); base part is the base-link twist in the base-link frame.
        tau: joint torques/forces, N m or N (N, n_joints), Pinocchio joint order.
        joint_positions: joint angles/displacements, rad or m (N, n_joints).
        joint_reference: reference joint positions, rad or m (N, n_joints); NaN without a task.
        base_position: base CoM position r0, inertial frame, m (N, 3).
        base_quaternion: base CoM frame orientation [qx, qy, qz, qw], inertial frame (N, 4).
        base_twist: base twist [v0; w0] of the base CoM, inertial frame, m/s and rad/s (N, 6).
        ee_position: end-effector frame origins, inertial frame, m (N, k, 3).
        ee_quaternion: end-effector frame orientations [qx, qy, qz, qw] (N, k, 4).
        com: system centre of mass, inertial frame, m (N, 3).
        momentum: [P; L]: linear momentum and angular momentum about the inertial origin,
            inertial frame, kg m/s and kg m^2/s (N, 6).
        energy: kinetic plus gravitational potential energy, J (N,).
        work: cumulative work of the joint torques since t[0], J (N,).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    joint_positions: np.ndarray
    joint_reference: np.ndarray
    base_position: np.ndarray
    base_quaternion: np.ndarray
    base_twist: np.ndarray
    ee_position: np.ndarray
    ee_quaternion: np.ndarray
    com: np.ndarray
    momentum: np.ndarray
    energy: np.ndarray
    work: np.ndarray

    @classmethod
    def allocate(cls, rows: int, nq: int, nv: int, n_joints: int, n_ee: int) -> Telemetry:
        """Zero-filled buffers for ``rows`` samples (references NaN)."""
        z = np.zeros
        return cls(
            t=z(rows), q=z((rows, nq)), v=z((rows, nv)), tau=z((rows, n_joints)),
            joint_positions=z((rows, n_joints)),
            joint_reference=np.full((rows, n_joints), np.nan),
            base_position=z((rows, 3)), base_quaternion=z((rows, 4)), base_twist=z((rows, 6)),
            ee_position=z((rows, n_ee, 3)), ee_quaternion=z((rows, n_ee, 4)),
            com=z((rows, 3)), momentum=z((rows, 6)), energy=z(rows), work=z(rows),
        )


@dataclass
class MechanismTelemetry(Arrays):
    """Recorded closed-chain mechanism run, one row per integration step. Coordinates
    ``q = [q#; q°]`` as in :class:`~freefloat.parallel.mechanism.ParallelMechanism`.

    Attributes:
        t: time, s (N,).
        platform: platform coordinates q#, m or rad (N, p).
        platform_reference: the reference q#_d (N, p).
        joints: the chains' joint coordinates q°, rad or m, chains in closure order (N, n_q - p).
        efforts: actuator efforts held over [t_k, t_k+1), N m or N (N, k); the last row, which
            starts no step, is NaN.
        drift: loop-closure residual max |qbar(q)|, m (N,).
        orientation_drift: residual of the angular constraints' position form, max over rows, rad
            (N,); 0 for a mechanism without angular constraints.
        sliding: the law's sliding variables ``s = -(edot + lambda e)``, ``e = q#_d - q#``, at each
X
    """

    t: np.ndarray
    platform: np.ndarray
    platform_reference: np.ndarray
    joints: np.ndarray
    efforts: np.ndarray
    drift: np.ndarray
    orientation_drift: np.ndarray
    sliding: np.ndarray


@dataclass
class PlantTelemetry(Arrays):
    """Recorded run of a plant (:func:`freefloat.dynamics.simulation.run_plant`), one row per
    recorded control period. Row ``k`` is the state at ``t[k]``; ``efforts[k]`` are held over
    [t_k, t_k+1).

    Attributes:
        t: time, s (N,).
        q: the plant's coordinates (N, nq) (a closed chain by coupling: Orsino's ``[q#; q°]``).
        v: the plant's velocity (N, nv).
        efforts: actuator efforts, N m or N (N, k).
        reference: the controller's reference (N, r) (platform control: q#_d); NaN without one.
        drift: largest loop-closure position residual, m (N,); 0 for a tree.
        orientation_drift: largest orientation residual, rad (N,); 0 without angular closures.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    efforts: np.ndarray
    reference: np.ndarray
    drift: np.ndarray
    orientation_drift: np.ndarray

    @classmethod
    def allocate(cls, rows: int, nq: int, nv: int, n_efforts: int, n_reference: int) -> PlantTelemetry:
        """Zero-filled buffers for ``rows`` samples (references NaN)."""
        z = np.zeros
        return cls(t=z(rows), q=z((rows, nq)), v=z((rows, nv)), efforts=z((rows, n_efforts)),
                   reference=np.full((rows, n_reference), np.nan), drift=z(rows), orientation_drift=z(rows))
