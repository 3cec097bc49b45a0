"""IEEE 488.2 arbitrary block data (7.7.6): definite-length ``#<n><length><bytes>`` with n
(1-9) digits of length, and indefinite ``#0<bytes>`` running to the message's end."""
from __future__ import annotations


def definite_block(data: bytes) -> bytes:
    """``data`` as a definite-length block."""
    count = str(len(data))
    return b"#" + str(len(count)).encode() + count.encode() + data


def block_end(text: bytes, at: int) -> int | None:
    """Where the block starting with ``#`` at ``text[at]`` ends (one past its last byte),
    or None when it is not a well-formed block of the bytes present."""
    if text[at:at + 1] != b"#" or not text[at + 1:at + 2].isdigit():
        return None
    n = int(text[at + 1:at + 2])
    if n == 0:
        return len(text)
    digits = text[at + 2:at + 2 + n]
    if len(digits) != n or not digits.isdigit():
        return None
    end = at + 2 + n + int(digits)
    return end if end <= len(text) else None


def block_payload(block: bytes) -> bytes:
    """The bytes a well-formed block holds (ValueError otherwise)."""
    end = block_end(block, 0)
    if end is None or end != len(block):
        raise ValueError("not one well-formed block")
    n = int(block[1:2])
    return block[2:] if n == 0 else block[2 + n:]
