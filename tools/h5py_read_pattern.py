#!/usr/bin/env python3
"""Read a yarnhom pattern exported to HDF5 with h5py + numpy and check it independently.

Usage: python3 tools/h5py_read_pattern.py FILE.h5

Checks the layout documented in schemas/hdf5.md without any yarnhom code: root attributes,
dataset dtypes and shapes, the `units` and `description` attributes of every dataset, the yarn
CSR ranges (they cover /yarns/vertices exactly, and the yarns use every vertex exactly once),
edge offsets of at most one tile whose sum per yarn is not (0, 0), finite values, positive
periods, radii and rest lengths, unit reference directors.

On success prints one line of JSON:
  {"kind": .., "vertices": .., "yarns": .., "period_m": [..], "radius_m": [..], "has_rest": ..}
and exits 0. On any inconsistency prints "FILE: problem" to stderr and exits 1 (2 for usage,
3 when h5py or numpy is missing).
"""

import json
import sys

try:
    import h5py
    import numpy as np
except ImportError as e:  # pragma: no cover - environment problem, not a file problem
    print(f"h5py_read_pattern: needs h5py and numpy: {e}", file=sys.stderr)
    sys.exit(3)


class Inconsistent(Exception):
    """The file breaks the layout or an invariant."""


ROOT_STRING_ATTRS = [
    "yarnhom_kind",
    "content_hash",
    "producer_name",
    "producer_version",
    "created_utc",
    "inputs",
    "name",
    "fabric",
    "origin",
]

# path -> (dtype, shape with "n"/"Y"/"Y+1" placeholders, units)
DATASETS = {
    "/period_m": ("float64", (2,), "m"),
    "/positions_m": ("float64", ("n", 3), "m"),
    "/edge_twist_rad": ("float64", ("n",), "rad"),
    "/yarns/radius_m": ("float64", ("Y",), "m"),
    "/yarns/vertex_start": ("uint64", ("Y+1",), "1"),
    "/yarns/vertices": ("uint32", ("n",), "1"),
    "/yarns/edge_offsets": ("int32", ("n", 2), "1"),
}
REST_DATASETS = {
    "/rest/edge_length_m": ("float64", ("n",), "m"),
    "/rest/vertex_curvature": ("float64", ("n", 2), "1"),
    "/rest/vertex_twist_rad": ("float64", ("n",), "rad"),
    "/rest/edge_reference_director": ("float64", ("n", 3), "1"),
    "/rest/vertex_reference_twist_rad": ("float64", ("n",), "rad"),
}


def as_str(value, what):
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, str):
        return value
    raise Inconsistent(f"{what} is not a string but {type(value).__name__}")


def load(f, path, spec, sizes):
    """Read a dataset, checking dtype, shape, units and description."""
    dtype, shape, units = spec
    if path not in f:
        raise Inconsistent(f"missing dataset {path}")
    ds = f[path]
    if not isinstance(ds, h5py.Dataset):
        raise Inconsistent(f"{path} is not a dataset")
    if ds.dtype != np.dtype(dtype):
        raise Inconsistent(f"dataset {path} has dtype {ds.dtype}, expected {dtype}")
    want = tuple(sizes[s] if isinstance(s, str) else s for s in shape)
    if ds.shape != want:
        raise Inconsistent(f"dataset {path} has shape {ds.shape}, expected {want}")
    for attr in ("units", "description"):
        if attr not in ds.attrs:
            raise Inconsistent(f"dataset {path} has no '{attr}' attribute")
    got_units = as_str(ds.attrs["units"], f"{path} units")
    if got_units != units:
        raise Inconsistent(f"dataset {path} has units '{got_units}', expected '{units}'")
    if not as_str(ds.attrs["description"], f"{path} description"):
        raise Inconsistent(f"dataset {path} has an empty description")
    data = ds[()]
    if data.dtype.kind == "f" and not np.all(np.isfinite(data)):
        raise Inconsistent(f"dataset {path} holds a non-finite value")
    return data


def check(path):
    with h5py.File(path, "r") as f:
        attrs = f.attrs
        for name in ROOT_STRING_ATTRS + ["schema_version"]:
            if name not in attrs:
                raise Inconsistent(f"missing root attribute '{name}'")
        strings = {name: as_str(attrs[name], f"root attribute '{name}'") for name in ROOT_STRING_ATTRS}
        kind = strings["yarnhom_kind"]
        if kind != "pattern":
            raise Inconsistent(f"yarnhom_kind is '{kind}', this tool reads 'pattern'")
        version = attrs["schema_version"]
        if not np.issubdtype(np.asarray(version).dtype, np.integer) or int(version) != 1:
            raise Inconsistent(f"schema_version is {version!r}, expected 1")
        if strings["fabric"] not in ("knit", "woven"):
            raise Inconsistent(f"fabric is '{strings['fabric']}', expected 'knit' or 'woven'")
        if not strings["content_hash"].startswith("sha256:") or len(strings["content_hash"]) != 71:
            raise Inconsistent(f"content_hash '{strings['content_hash']}' is not sha256:<64 hex>")
        try:
            inputs = json.loads(strings["inputs"])
        except json.JSONDecodeError as e:
            raise Inconsistent(f"root attribute 'inputs' is not JSON: {e}") from None
        if not isinstance(inputs, list) or not all(
            isinstance(i, dict) and set(i) == {"kind", "content_hash", "path"} for i in inputs
        ):
            raise Inconsistent("root attribute 'inputs' is not a list of {kind, content_hash, path}")

        if "/positions_m" not in f or f["/positions_m"].ndim != 2:
            raise Inconsistent("missing or malformed dataset /positions_m")
        if "/yarns/radius_m" not in f or f["/yarns/radius_m"].ndim != 1:
            raise Inconsistent("missing or malformed dataset /yarns/radius_m")
        n = f["/positions_m"].shape[0]
        y = f["/yarns/radius_m"].shape[0]
        sizes = {"n": n, "Y": y, "Y+1": y + 1}
        d = {p: load(f, p, spec, sizes) for p, spec in DATASETS.items()}

        has_rest = "rest" in f
        rest = {}
        if has_rest:
            if not isinstance(f["rest"], h5py.Group):
                raise Inconsistent("/rest is not a group")
            rest = {p: load(f, p, spec, sizes) for p, spec in REST_DATASETS.items()}

    period = d["/period_m"]
    if not np.all(period > 0):
        raise Inconsistent(f"/period_m must be positive, is {period.tolist()}")
    radius = d["/yarns/radius_m"]
    if y == 0:
        raise Inconsistent("a pattern needs at least one yarn")
    if not np.all(radius > 0):
        raise Inconsistent(f"/yarns/radius_m must be positive, is {radius.tolist()}")

    start = d["/yarns/vertex_start"].astype(np.int64)
    if start[0] != 0 or start[-1] != n or np.any(np.diff(start) < 0):
        raise Inconsistent(
            f"/yarns/vertex_start {start.tolist()} is not a CSR row pointer over {n} rows"
        )
    vertices = d["/yarns/vertices"].astype(np.int64)
    if np.any(vertices >= n):
        raise Inconsistent(f"/yarns/vertices holds an index >= {n}")
    counts = np.bincount(vertices, minlength=n)
    if np.any(counts > 1):
        bad = int(np.flatnonzero(counts > 1)[0])
        raise Inconsistent(f"vertex {bad} is used {int(counts[bad])} times by the yarns, expected once")
    if np.any(counts == 0):
        raise Inconsistent(f"vertex {int(np.flatnonzero(counts == 0)[0])} belongs to no yarn")
    offsets = d["/yarns/edge_offsets"]
    if np.any(np.abs(offsets) > 1):
        raise Inconsistent("/yarns/edge_offsets holds an offset of more than one tile")
    for k in range(y):
        lo, hi = int(start[k]), int(start[k + 1])
        if hi - lo < 3:
            raise Inconsistent(f"yarn {k} has {hi - lo} vertices, a closed yarn needs 3")
        if np.all(offsets[lo:hi].sum(axis=0) == 0):
            raise Inconsistent(f"yarn {k}: edge offsets sum to (0, 0), the yarn is not periodic")

    if has_rest:
        if not np.all(rest["/rest/edge_length_m"] > 0):
            raise Inconsistent("/rest/edge_length_m must be positive")
        norms = np.linalg.norm(rest["/rest/edge_reference_director"], axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-3):
            raise Inconsistent("/rest/edge_reference_director holds a non-unit vector")

    return {
        "kind": kind,
        "vertices": int(n),
        "yarns": int(y),
        "period_m": [float(v) for v in period],
        "radius_m": [float(v) for v in radius],
        "has_rest": bool(has_rest),
    }


def main(argv):
    if len(argv) != 2:
        print("usage: h5py_read_pattern.py FILE.h5", file=sys.stderr)
        return 2
    path = argv[1]
    try:
        summary = check(path)
    except Inconsistent as e:
        print(f"{path}: {e}", file=sys.stderr)
        return 1
    except (OSError, KeyError, ValueError, TypeError) as e:
        print(f"{path}: cannot read as a yarnhom pattern: {e}", file=sys.stderr)
        return 1
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
