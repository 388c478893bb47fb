"""Reads an HDF5 file written by `yarnhom trace export --format hdf5` the way a training loader
would: discovers the layout from the JSON manifest only, checks every entry against what h5py
sees (path, shape, dtype, `units` and `description` attributes) and that nothing in the file is
missing from the manifest. Prints a summary as JSON."""

import json
import sys

import h5py
import numpy as np


def all_datasets(group):
    """Absolute paths of every dataset in the file."""
    found = []
    group.visititems(lambda name, obj: found.append("/" + name) if isinstance(obj, h5py.Dataset) else None)
    return found


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def main(path):
    with h5py.File(path, "r") as f:
        manifest = json.loads(f["manifest"][()])
        listed = {entry["path"]: entry for entry in manifest["datasets"]}
        present = set(all_datasets(f))
        if set(listed) != present:
            raise SystemExit(f"manifest {sorted(listed)} != file {sorted(present)}")
        for entry in manifest["datasets"]:
            dataset = f[entry["path"]]
            if list(dataset.shape) != entry["shape"]:
                raise SystemExit(f"{entry['path']}: shape {dataset.shape} != {entry['shape']}")
            dtype = "string" if h5py.check_string_dtype(dataset.dtype) else dataset.dtype.name
            if dtype != entry["dtype"]:
                raise SystemExit(f"{entry['path']}: dtype {dtype} != {entry['dtype']}")
            for attr in ("units", "description"):
                if text(dataset.attrs[attr]) != entry[attr]:
                    raise SystemExit(f"{entry['path']}: attribute {attr} differs from the manifest")
        positions = f["/mesh/drape/positions_m"][...]
        print(json.dumps({
            "positions_shape": list(positions.shape),
            "positions_finite": bool(np.isfinite(positions).all()),
            "frames": f["/mesh/drape/frame"][...].tolist(),
            "metrics": sorted(name for name in f["/metrics"]),
            "datasets": len(manifest["datasets"]),
            "producers": [m.get("producer_name") for m in manifest["trace_metadata"]],
            "input": manifest["input"],
        }))


if __name__ == "__main__":
    main(sys.argv[1])
