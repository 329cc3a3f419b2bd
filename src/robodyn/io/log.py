"""One tabular format for every trajectory and log robodyn reads or writes.

Written by ``robodyn simulate --csv`` (:meth:`robodyn.simulation.Trajectory.to_csv`),
``robodyn excite --out`` and :func:`write_log`; read by ``robodyn torques``, ``robodyn
identify``, ``robodyn simulate --reference``, :func:`read_log`, :func:`read_trajectory` and
:meth:`Trajectory.from_csv <robodyn.simulation.Trajectory.from_csv>`. One header row, one row
per sample, SI units, radians::

    t, q:<coordinate>..., v:<dof>..., a:<dof>..., tau:<dof>..., <extra>...

``<coordinate>`` and ``<dof>`` are the names of ``Model.q_names`` (nq) and
``Model.dof_names`` (nv): the joint's name, or ``<joint>:x`` ... ``<joint>:qw`` and
``<joint>:vx`` ... ``<joint>:wz`` for the entries of a free joint. ``t`` increases
strictly. ``q`` is required; ``v``, ``a`` and ``tau`` are optional, each for all its entries
or none; the column order is free and unknown columns are kept as extras (``energy``,
``lyapunov``, contact forces, ... see ``Trajectory.to_csv``). Empty fields and ``nan`` are
missing values: such rows are reported by their line numbers and never used.

Two encodings, chosen by the file's suffix: CSV (any suffix but ``.parquet``, full float
precision) and Parquet (``.parquet``, one float64 column per name; needs ``pyarrow``,
``pip install "robodyn[parquet]"``), for large logs.

A table already in memory with these columns (a pandas DataFrame, one partition of a Dask
DataFrame) is read by :func:`read_frame`, with the same checks (:func:`table_log`).

The older spelling of identification logs, ``time, q_<joint>, qd_<joint>, qdd_<joint>,
tau_<joint>``, is still read, with a :class:`~robodyn.errors.RobodynDeprecationWarning`.
"""

from __future__ import annotations

import csv
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._deprecated import renamed_attribute, renamed_keywords, warn_renamed
from ..errors import RobodynWarning
from ..files import atomic_path

KINDS = ("q", "v", "a", "tau")
OLD_KINDS = {"q": "q", "qd": "v", "qdd": "a", "tau": "tau"}  # identification logs before the one format


@dataclass(frozen=True)
class Log:
    """Samples ``t`` (N,), ``q`` (N, nq) and, when known, ``v``, ``a``, ``tau`` (N, nv);
    ``extra`` maps the other columns' names to their (N,) samples."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    tau: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def rows(self, sl) -> "Log":
        """The samples ``sl`` (a slice or index array) of every array."""
        cut = lambda x: None if x is None else x[sl]  # noqa: E731
        return Log(*(cut(x) for x in (self.t, self.q, self.v, self.a, self.tau)),
                   extra={k: x[sl] for k, x in self.extra.items()})

    qd = renamed_attribute("qd", "v")
    qdd = renamed_attribute("qdd", "a")


def columns(model, kind: str) -> list[str]:
    """The column names of one kind: ``q:<coordinate>`` (nq) or ``v:``, ``a:``, ``tau:<dof>`` (nv)."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return [f"{kind}:{n}" for n in (model.q_names if kind == "q" else model.dof_names)]


@renamed_keywords(qd="v", qdd="a")
def write_log(path, model, t, q, *, v=None, a=None, tau=None, extra=None) -> Path:
    """Write samples in the format of the module docstring (CSV, or Parquet for ``.parquet``).

    ``t`` (N,), ``q`` (N, nq), ``v``, ``a``, ``tau`` (N, nv) or None; ``extra`` a mapping of
    further column names to (N,) arrays. Written atomically (whole or not at all).
    """
    path = Path(path)
    t = np.asarray(t, dtype=float).reshape(-1)
    names, cols = ["t"], [t[:, None]]
    for kind, x in zip(KINDS, (q, v, a, tau)):
        if x is None:
            continue
        width = model.nq if kind == "q" else model.nv
        x = np.asarray(x, dtype=float)
        if x.shape != (t.shape[0], width):
            raise ValueError(f"{kind}: expected shape ({t.shape[0]}, {width}), got {x.shape}")
        names += columns(model, kind)
        cols.append(x)
    for name, x in (extra or {}).items():
        x = np.asarray(x, dtype=float)
        if x.shape != t.shape:
            raise ValueError(f"extra column {name!r}: expected shape {t.shape}, got {x.shape}")
        if name in names:
            raise ValueError(f"extra column {name!r} repeats a column of the log")
        names.append(name)
        cols.append(x[:, None])
    data = np.hstack(cols)
    with atomic_path(path) as tmp:
        if _parquet(path):
            pa, pq = _pyarrow()
            pq.write_table(pa.table({n: data[:, k] for k, n in enumerate(names)}), tmp)
        else:
            with open(tmp, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(names)
                w.writerows([[repr(x) for x in row] for row in data.tolist()])
    return path


def read_log(path, model, *, require_tau: bool = False) -> Log:
    """Read a log or trajectory for ``model`` (format in the module docstring).

    Raises ``ValueError`` naming the file for: missing columns (listed), a kind given for
    only some entries, non-numeric fields (line and column), missing values (lines listed),
    time not strictly increasing (first offending line), fewer than 2 rows. ``require_tau``:
    the ``tau`` columns must be there (identification).
    """
    path = Path(path)
    header, data, lines, text = _read_table(path)
    return table_log(header, data, model, source=path, lines=lines, text=text, require_tau=require_tau,
                     stacklevel=3)


def read_frame(frame, model, *, source="data frame", require_tau: bool = False) -> Log:
    """A log of a table in memory with the columns of the format (a pandas DataFrame, one
    partition of a Dask DataFrame): :func:`table_log` of its column names and values. A
    column that does not convert to float counts as text (kept out, or an error when it is
    one of the log's columns); rows are numbered as lines of the frame written as CSV (the
    header on line 1). ``source`` names the frame in the messages."""
    header = [str(name).strip() for name in frame.columns]
    data, text = np.full((len(frame), len(header)), np.nan), {}
    for c, name in enumerate(frame.columns):
        try:
            data[:, c] = np.asarray(frame[name].to_numpy(), dtype=float)
        except (TypeError, ValueError):
            text[c] = f"{source}: column {header[c]!r} is not numeric"
    return table_log(header, data, model, source=source, lines=np.arange(len(frame)) + 2, text=text,
                     require_tau=require_tau, stacklevel=3)


def table_log(header, data, model, *, source, lines=None, text=None, require_tau: bool = False,
              stacklevel: int = 2) -> Log:
    """The log of a table read by :func:`read_log` or :func:`read_frame`: ``header`` (ncols)
    column names, ``data`` (N, ncols) floats with NaN for empty fields, ``lines`` (N,) the
    line of each row in messages (default 2, 3, ...), ``text`` ``{column: message}`` for the
    columns holding text. Checks and errors as :func:`read_log`'s, naming ``source``;
    ``stacklevel``: the frame the warnings point at (2: the caller of this function)."""
    data = np.asarray(data, dtype=float)
    lines = np.arange(data.shape[0]) + 2 if lines is None else np.asarray(lines)
    text = {} if text is None else text
    header = _new_spelling(header, model, source, stacklevel + 2)
    index = {name: k for k, name in enumerate(header)}
    if len(index) != len(header):
        raise ValueError(f"{source}: repeated column names {sorted({h for h in header if header.count(h) > 1})}")
    need = ["t"] + columns(model, "q") + (columns(model, "tau") if require_tau else [])
    missing = [n for n in need if n not in index]
    if missing:
        raise ValueError(f"{source}: missing columns {missing} for model {model.name!r}; expected t, q:<coordinate>"
                         f"{', tau:<dof>' if require_tau else ''} with coordinates {model.q_names}")
    kinds = []
    for kind in KINDS:
        names = columns(model, kind)
        present = [n for n in names if n in index]
        if present and len(present) != len(names):
            raise ValueError(f"{source}: {kind} given for some entries only; missing columns "
                             f"{[n for n in names if n not in index]}")
        if present:
            kinds.append(kind)
    wanted = {"t"} | {n for kind in kinds for n in columns(model, kind)}
    for c in sorted(text):
        if header[c] in wanted:
            raise ValueError(text[c])
    if text:
        warnings.warn(f"{source}: columns {[header[c] for c in sorted(text)]} hold text and are not read",
                      RobodynWarning, stacklevel=stacklevel)
        keep = [k for k in range(len(header)) if k not in text]
        header, data = [header[k] for k in keep], data[:, keep]
        index = {name: k for k, name in enumerate(header)}
    blocks = {kind: [index[n] for n in columns(model, kind)] for kind in kinds}
    if data.shape[0] < 2:
        raise ValueError(f"{source}: {data.shape[0]} data rows, need at least 2")
    bad = ~np.isfinite(data).all(axis=1)
    if bad.any():
        shown = lines[bad][:20].tolist()
        raise ValueError(f"{source}: {int(bad.sum())} rows with missing or non-finite values at lines {shown}"
                         f"{' ...' if bad.sum() > 20 else ''}; remove or repair them")
    t = data[:, index["t"]].copy()
    step = np.diff(t)
    if np.any(step <= 0):
        k = int(np.flatnonzero(step <= 0)[0])
        raise ValueError(f"{source}: time not strictly increasing at line {lines[k + 1]} "
                         f"(t = {float(t[k + 1])!r} after {float(t[k])!r} on line {lines[k]})")
    extra = {h: data[:, k].copy() for h, k in index.items() if h not in wanted}
    return Log(t=t, **{kind: data[:, cols].copy() for kind, cols in blocks.items()}, extra=extra)


def read_trajectory(path, model):
    """``(t, q, v, a)`` of a trajectory file: :func:`read_log`, with ``v`` and ``a``, when
    their columns are absent, from a cubic spline through ``q`` (``nq == nv`` only: a
    floating-base trajectory needs its ``v`` and ``a`` columns)."""
    from scipy.interpolate import CubicSpline

    log = read_log(path, model)
    v, a = log.v, log.a
    if v is None or a is None:
        if model.nq != model.nv:
            raise ValueError(f"{path}: a floating-base trajectory needs its v and a columns")
        spline = CubicSpline(log.t, log.q, axis=0)
        v = spline(log.t, 1) if v is None else v
        a = spline(log.t, 2) if a is None else a
    return log.t, log.q, v, a


def read_csv(model, path):
    """Deprecated: ``read_trajectory(path, model)``."""
    warn_renamed("read_csv(model, path)", "read_trajectory(path, model)", "robodyn")
    return read_trajectory(path, model)


def coordinate_names(model) -> tuple[list[str], list[str]]:
    """Deprecated: ``(model.q_names, model.dof_names)``."""
    warn_renamed("coordinate_names(model)", "model.q_names, model.dof_names", "robodyn")
    return model.q_names, model.dof_names


def _parquet(path: Path) -> bool:
    return path.suffix.lower() == ".parquet"


def _pyarrow():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise ValueError('Parquet files need pyarrow: pip install "robodyn[parquet]"') from None
    return pa, pq


def _read_table(path: Path) -> tuple[list[str], np.ndarray, np.ndarray, dict]:
    """``(header, data (N, ncols) with NaN for empty or text fields, file line of each row,
    {column: message of its first text field})``."""
    if _parquet(path):
        _, pq = _pyarrow()
        try:
            table = pq.read_table(path)
        except (OSError, ValueError) as e:  # pyarrow's ArrowInvalid is a ValueError
            raise ValueError(f"{path}: not a Parquet file ({e})") from None
        header = [str(n).strip() for n in table.column_names]
        try:
            data = np.column_stack([np.asarray(c.to_numpy(zero_copy_only=False), dtype=float)
                                    for c in table.columns]) if header else np.empty((0, 0))
        except (TypeError, ValueError) as e:
            raise ValueError(f"{path}: non-numeric column ({e})") from None
        return header, data.reshape(table.num_rows, len(header)), np.arange(table.num_rows) + 1, {}
    try:
        with open(path, newline="") as f:
            reader = csv.reader(f)
            try:
                header = [h.strip() for h in next(reader)]
            except StopIteration:
                raise ValueError(f"{path}: empty file, expected a header row") from None
            rows = [(reader.line_num, row) for row in reader if any(cell.strip() for cell in row)]
    except (UnicodeDecodeError, csv.Error) as e:
        raise ValueError(f"{path}: not a CSV text file ({e})") from None
    data, text = np.full((len(rows), len(header)), np.nan), {}
    for r, (line, row) in enumerate(rows):
        if len(row) > len(header):
            raise ValueError(f"{path}: line {line} has {len(row)} fields, the header {len(header)}")
        for c, cell in enumerate(row):
            cell = cell.strip()
            if cell:
                try:
                    data[r, c] = float(cell)
                except ValueError:
                    text.setdefault(c, f"{path}: line {line}, column {header[c]!r}: not a number: {cell!r}")
    return header, data, np.array([ln for ln, _ in rows], dtype=np.int64), text


def _new_spelling(header: list[str], model, path, stacklevel: int) -> list[str]:
    """The header with the old identification spelling (``time``, ``q_<joint>``,
    ``qd_<joint>``, ``qdd_<joint>``, ``tau_<joint>``) renamed, with one warning (at
    ``stacklevel``, as for ``warnings.warn`` called here)."""
    one_dof = set(model.body_joint_names) & set(model.dof_names)  # the only joints the old spelling had
    old = {"time": "t"}
    for prefix, kind in OLD_KINDS.items():
        old.update({f"{prefix}_{j}": f"{kind}:{j}" for j in one_dof})
    if "t" in header or not any(h in old for h in header):
        return header
    warn_renamed(f"{path}: columns time, q_<joint>, qd_<joint>, qdd_<joint>, tau_<joint>",
                 "t, q:<joint>, v:<joint>, a:<joint>, tau:<joint>", "log file", stacklevel=stacklevel)
    return [old.get(h, h) for h in header]
