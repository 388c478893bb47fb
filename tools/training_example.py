#!/usr/bin/env python3
"""Load a training set written by `yarnhom trace export --format training` with h5py and numpy
only, the way a MeshGraphNets-style loader would, and compute its acceleration targets.

Usage: python3 tools/training_example.py DIR [--json]

DIR holds `meta.json` and one HDF5 file per split (`train.h5`, ...), each sequence a group
`/<index>` with `world_pos [T, N, 3]`, `mesh_pos [N, 3]`, `node_type [N, 1]`, `edges [E, 2]`,
`radius [N, 1]` and `dt` (layout: crates/yarnhom-trace/src/export/training.rs, schemas/hdf5.md).
For every sequence this checks each field against the `features` of meta.json (dtype, and shape
with -1 for sizes that vary), prints the shapes, and computes MeshGraphNets' learned quantity,
the acceleration target `x[t+1] - 2 x[t] + x[t-1]` (metres per frame squared; divided by dt^2
in m/s^2) for t = 1 .. T-2, checking that it is finite. Targets are computed in float64 from
the float32 positions, and summarized per node type (0 NORMAL: what a model is trained on;
3 HANDLE: prescribed motion, given to the model as input).

Prints one paragraph per sequence, or with --json one JSON object:
  {"dt": .., "sequences": [{"split", "group", "source", "yarns", "shapes", "dtypes",
    "targets_shape", "targets_finite", "targets": {"<node type>": {"nodes", "min_m", "max_m",
    "min_m_s2", "max_m_s2"}}}]}
Exits 1 with "DIR: problem" on stderr when the data set breaks its meta.json, 2 for usage, 3
when h5py or numpy is missing.
"""

import json
import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as e:  # pragma: no cover - environment problem, not a data problem
    print(f"training_example: needs h5py and numpy: {e}", file=sys.stderr)
    sys.exit(3)


class Inconsistent(Exception):
    """The data set does not match its meta.json."""


def check_field(name, dataset, feature, frames):
    """The dataset has the dtype and shape meta.json gives (-1: any size; the frame count of a
    dynamic field is the sequence's)."""
    if dataset.dtype.name != feature["dtype"]:
        raise Inconsistent(f"{dataset.name}: dtype {dataset.dtype.name}, meta.json says {feature['dtype']}")
    shape = list(feature["shape"])
    if feature["type"] == "dynamic":
        shape[0] = frames
    if len(dataset.shape) != len(shape) or any(s not in (-1, d) for s, d in zip(shape, dataset.shape)):
        raise Inconsistent(f"{dataset.name}: shape {dataset.shape}, meta.json says {shape}")


def load_sequence(group, meta, info):
    """The fields of one sequence as numpy arrays, checked against meta.json."""
    fields = {}
    for name in meta["field_names"]:
        if name not in group:
            raise Inconsistent(f"{group.name}: no dataset {name}")
        check_field(name, group[name], meta["features"][name], info["trajectory_length"])
        fields[name] = group[name][()]
    fields["dt"] = float(group["dt"][()])
    return fields


def acceleration_targets(world_pos):
    """MeshGraphNets' target: x[t+1] - 2 x[t] + x[t-1], shape [T-2, N, 3], in float64."""
    x = world_pos.astype(np.float64)
    return x[2:] - 2.0 * x[1:-1] + x[:-2]


def summarize(fields, info):
    """Shapes, dtypes and the acceleration targets per node type of one sequence."""
    targets = acceleration_targets(fields["world_pos"])
    node_type = fields["node_type"][:, 0]
    dt = fields["dt"]
    per_type = {}
    for code in sorted(set(node_type.tolist())):
        chosen = targets[:, node_type == code, :].reshape(-1, 3)
        per_type[str(code)] = {
            "nodes": int((node_type == code).sum()),
            "min_m": chosen.min(axis=0).tolist(),
            "max_m": chosen.max(axis=0).tolist(),
            "min_m_s2": (chosen.min(axis=0) / dt**2).tolist(),
            "max_m_s2": (chosen.max(axis=0) / dt**2).tolist(),
        }
    edges = fields["edges"]
    nodes = fields["world_pos"].shape[1]
    if edges.size and (edges.min() < 0 or edges.max() >= nodes):
        raise Inconsistent(f"{info['split']}/{info['group']}: edges index past the {nodes} nodes")
    return {
        "split": info["split"],
        "group": info["group"],
        "source": info["source"],
        "yarns": info["yarns"],
        "dt": dt,
        "shapes": {name: list(fields[name].shape) for name in sorted(fields) if name != "dt"},
        "dtypes": {name: fields[name].dtype.name for name in sorted(fields) if name != "dt"},
        "targets_shape": list(targets.shape),
        "targets_finite": bool(np.isfinite(targets).all()),
        "targets": per_type,
    }


def main(folder, as_json):
    with open(os.path.join(folder, "meta.json")) as f:
        meta = json.load(f)
    summaries = []
    for split, split_info in sorted(meta["splits"].items()):
        with h5py.File(os.path.join(folder, split_info["file"]), "r") as f:
            if len(f.keys()) != split_info["sequences"]:
                raise Inconsistent(f"{split_info['file']}: {len(f.keys())} groups, meta.json says {split_info['sequences']}")
            for info in (s for s in meta["sequences"] if s["split"] == split):
                fields = load_sequence(f[info["group"]], meta, info)
                if abs(fields["dt"] - meta["dt"]) > 1e-9 * abs(meta["dt"]):
                    raise Inconsistent(f"{split}/{info['group']}: dt {fields['dt']} != meta.json's {meta['dt']}")
                summaries.append(summarize(fields, info))
    if as_json:
        print(json.dumps({"dt": meta["dt"], "sequences": summaries}))
    else:
        print_summaries(summaries)
    broken = [f"{s['split']}/{s['group']}" for s in summaries if not s["targets_finite"]]
    if broken:
        raise Inconsistent(f"non-finite acceleration targets in {', '.join(broken)}")


def print_summaries(summaries):
    """One paragraph per sequence: shapes, and the targets' range per node type in m/s^2."""
    for s in summaries:
        shapes = ", ".join(f"{name} {tuple(shape)} {s['dtypes'][name]}" for name, shape in s["shapes"].items())
        print(f"{s['split']}/{s['group']} ({s['source']}, yarns {s['yarns']!r}, dt {s['dt']} s): {shapes}")
        finite = "finite" if s["targets_finite"] else "NOT FINITE"
        print(f"  acceleration targets x[t+1] - 2 x[t] + x[t-1]: {tuple(s['targets_shape'])}, {finite}")
        for code, t in s["targets"].items():
            low = ", ".join(f"{v:.6g}" for v in t["min_m_s2"])
            high = ", ".join(f"{v:.6g}" for v in t["max_m_s2"])
            print(f"    node type {code} ({t['nodes']} nodes): from ({low}) to ({high}) m/s^2")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--json"]
    if len(args) != 1:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        sys.exit(2)
    try:
        main(args[0], "--json" in sys.argv[1:])
    except (Inconsistent, KeyError, OSError) as e:
        print(f"{args[0]}: {e}", file=sys.stderr)
        sys.exit(1)
