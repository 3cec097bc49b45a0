"""A dataset's value read through HDF5's own calls, as h5py's ``dataset[()]`` gives it:
the codes and texts a read returns and every dataset a table of checksums hashes.

h5py's cost is per object, and its first read of a dataset object (its fast reader, its
type and selection checks) costs 60 to 100 us where HDF5's read itself costs 10 to 40: a
shot is read as a handful of such datasets, so these few calls are most of a read's time.
"""
from __future__ import annotations

import functools

import numpy as np


def dataset_value(dataset_id):
    """The value of the dataset ``dataset_id`` (an h5py DatasetID) as h5py's ``[()]`` reads
    it: a numpy array of the stored type (a numpy scalar for a scalar dataset) for integers
    and floats, bytes for a scalar variable-length text; any other kind through h5py itself.
    HDF5's fletcher32 check runs as in h5py (an OSError where a chunk is damaged)."""
    import h5py

    kind = dataset_id.get_type()
    shape = dataset_id.shape
    cls = kind.get_class()
    if cls in (h5py.h5t.INTEGER, h5py.h5t.FLOAT) and shape is not None:
        values = np.empty(shape, dtype=kind.dtype)
        if values.size:
            dataset_id.read(h5py.h5s.ALL, h5py.h5s.ALL, values)
        return values if shape else values[()]
    if cls == h5py.h5t.STRING and shape == () and kind.is_variable_str():
        text = np.empty((), dtype=h5py.string_dtype())
        dataset_id.read(h5py.h5s.ALL, h5py.h5s.ALL, text, mtype=_variable_text(kind.get_cset()))
        return text[()]
    return h5py.Dataset(dataset_id)[()]


def member_value(group, name: str):
    """The value of the dataset ``group[name]`` (dataset_value), opened through HDF5's own
    call: no h5py object made (KeyError where there is none)."""
    import h5py

    try:
        return dataset_value(h5py.h5o.open(group.id, name.encode()))
    except KeyError:
        raise KeyError(name) from None


@functools.cache
def _variable_text(charset: int):
    """The memory type h5py reads a variable-length text of ``charset`` with: bytes."""
    import h5py

    return h5py.h5t.py_create(h5py.string_dtype("utf-8" if charset == h5py.h5t.CSET_UTF8 else "ascii"))
