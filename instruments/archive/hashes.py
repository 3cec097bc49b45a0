"""The SHA-256 of one value as a reader reads it back, the unit of every table of
checksums (instruments/archive/digest.py): a dataset's dtype, shape and bytes, a text's
UTF-8 bytes, an attribute's value."""
from __future__ import annotations

import hashlib
import json

import numpy as np


def sha(data: bytes) -> str:
    """The SHA-256 of ``data``, hex."""
    return hashlib.sha256(data).hexdigest()


def value_digest(value) -> str:
    """The row of a dataset holding ``value`` (a text, or what numpy makes an array of):
    the SHA-256 of its dtype, shape and bytes; of "s" and its UTF-8 bytes for a text."""
    if isinstance(value, (bytes, str)):
        return sha(b"s" + (value.encode() if isinstance(value, str) else value))
    value = np.asarray(value)
    return sha(f"{value.dtype.str}{value.shape}".encode() + np.ascontiguousarray(value).tobytes())


def attribute_digest(value) -> str:
    """The row of an attribute holding ``value`` as h5py reads it back (a text, a numpy
    scalar or array, an array of texts); a writer gives it the value it writes, which h5py
    reads back alike for a text, a list of texts and a numpy scalar."""
    if isinstance(value, list):
        value = np.array(value, dtype=object)
    if isinstance(value, (bytes, str)):
        return sha(b"s" + (value.encode() if isinstance(value, str) else value))
    value = np.asarray(value)
    if value.dtype.kind == "O":
        return sha(json.dumps([v.decode() if isinstance(v, bytes) else str(v) for v in value.ravel()]).encode())
    return sha(f"{value.dtype.str}{value.shape}".encode() + np.ascontiguousarray(value).tobytes())
