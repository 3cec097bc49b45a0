"""A dataset's value and an attribute's, read through HDF5's own calls as h5py gives them
(``dataset[()]``, ``obj.attrs[name]``, ``list(obj.attrs)``): the codes, texts and metadata
a read returns, and every item a table of checksums hashes.

h5py's cost is per object: its first read of a dataset object (its fast reader, its type
and selection checks) costs 60 to 100 us where HDF5's read itself costs 10 to 40, an
attribute 35 us where HDF5's own calls cost 25, an object looked up by name (``g[name]``)
35 us where HDF5 opens it in 7. A shot is a few dozen such items, so these calls are most
of what a read and ``rig verify`` spend on it.
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
    call, as ``group[name]`` opens it (its errors), but no h5py object made."""
    import h5py

    return dataset_value(h5py.h5o.open(group.id, name.encode()))


@functools.cache
def _variable_text(charset: int):
    """The memory type h5py reads a variable-length text of ``charset`` with: bytes."""
    import h5py

    return h5py.h5t.py_create(h5py.string_dtype("utf-8" if charset == h5py.h5t.CSET_UTF8 else "ascii"))


def attribute_names(obj) -> list:
    """The names of ``obj``'s attributes (an h5py object or its HDF5 identifier), as h5py's
    ``list(obj.attrs)`` gives them, in the order of their names."""
    import h5py

    names: list = []

    def add(name, *_):
        try:
            names.append(name.decode("utf8"))
        except UnicodeDecodeError:  # as h5py: the bytes
            names.append(name)

    h5py.h5a.iterate(hdf5_id(obj), add)
    return names


def attribute_value(obj, name: str):
    """The attribute ``name`` of ``obj`` (an h5py object or its HDF5 identifier) as h5py's
    ``obj.attrs[name]`` reads it, through HDF5's own calls for what a table of checksums
    holds most: a text (str), a list of texts (an array of str), an integer or float scalar;
    anything else through h5py itself. It fails as h5py does (KeyError where there is no
    such attribute, or where HDF5 cannot open it), naming the attribute (HDF5's own words
    name it only where the object keeps its attributes compact, up to 8 of them)."""
    import h5py

    try:
        attribute = h5py.h5a.open(hdf5_id(obj), name.encode())
    except KeyError as exc:
        raise KeyError(f"attribute {name!r}: {exc.args[0] if exc.args else 'cannot be opened'}") from None
    kind = attribute.get_type()
    cls = kind.get_class()
    shape = attribute.shape
    if cls == h5py.h5t.STRING and kind.is_variable_str() and shape is not None and len(shape) <= 1:
        raw = np.empty(shape, dtype=h5py.string_dtype())
        attribute.read(raw, mtype=_variable_text(kind.get_cset()))
        texts = [b.decode("utf-8", "surrogateescape") for b in raw.flat]
        return texts[0] if shape == () else np.array(texts, dtype=h5py.string_dtype()).reshape(shape)
    if cls in (h5py.h5t.INTEGER, h5py.h5t.FLOAT) and shape == ():
        value = np.empty((), dtype=kind.dtype)
        attribute.read(value)
        return value[()]
    return h5py_object(obj).attrs[name]


def attribute_or(obj, name: str, default=None):
    """attribute_value(), or ``default`` where ``obj`` has no attribute ``name``, as h5py's
    ``obj.attrs.get`` (which fails where HDF5 cannot tell)."""
    import h5py

    if not h5py.h5a.exists(hdf5_id(obj), name.encode()):
        return default
    return attribute_value(obj, name)


def h5py_object(obj):
    """``obj`` as an h5py object (a Group or a Dataset) where it is an HDF5 identifier."""
    import h5py

    if isinstance(obj, h5py.HLObject):
        return obj
    return h5py.Group(obj) if isinstance(obj, h5py.h5g.GroupID) else h5py.Dataset(obj)


def hdf5_id(obj):
    """The HDF5 identifier of ``obj`` (an h5py object, or the identifier itself)."""
    import h5py

    return obj.id if isinstance(obj, h5py.HLObject) else obj
