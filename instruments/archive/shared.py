"""The shared groups a shot links to (``/shared/<key>``: its scene's text and settings, its
truth's forces), checked once per version of the file that holds them.

A scene's shared group lies in a part file, written once and never changed (layouts 3 and 4),
or in a layout-2 archive, replaced whole by each transaction. A version of that file is told
from another by links.file_identity (inode, size, modification time): the first read of a
shot that links to a group checks the group's whole table of checksums; the next reads of
the same version take what that read found (its objects' addresses, its scene texts and,
for the truth, its forces) and read nothing of it again. A file replaced or damaged on disk
(a new identity) is read and checked again before anything of it is returned.

The forces are the bulk (a published scene's: 7 arrays of 30,001 float64, 1.7 MB, stored
gzipped): those of the last ``FORCES_KEPT`` groups read are kept, read-only, and every read
of one of them returns the same arrays in a dict of its own. The first read of a version
reads them once: its check takes their rows of the table from the values read. A read that
skips the checksums (``Archive.read(verify=False)``) takes the forces kept for that version
of the file too, or reads them and keeps them as unchecked, which a checked read never takes:
it reads them again and checks them against the group's table.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass

from ..errors import InstrumentError
from .compare import damage
from .hashes import value_digest
from .links import file_identity, truth_item
from .stored import links_below, stored_rows, table_text
from .values import member_value
from .verify import addresses

FORCES_KEPT = 4  # the shared groups whose truth forces are kept (a published scene's: 1.7 MB each)


@dataclass(frozen=True)
class SoundGroup:
    """A shared group found intact: the identity of the file it was checked in
    (links.file_identity), {address: path} of its objects, its scene texts ({"scene_text",
    "settings"}, as stored)."""

    identity: tuple | None
    addresses: dict
    texts: dict


@dataclass(frozen=True)
class Shared:
    """What a shot links to, checked: its stored table (text; None where unreadable),
    {address: path} of the shared objects it links to, the scene texts of the group its own
    scene_text links to (None where none, or not intact) and the truth's forces of the group
    its truth links to ({name: read-only array in N}; None where not asked for or none)."""

    table: str | None
    linked: dict
    scene: dict | None
    truth: dict | None


class SharedGroups:
    """The shared groups an Archive's reads have checked, by (file, key): each checked once
    per version of its file; the truth forces of the last ``kept`` read."""

    def __init__(self, kept: int = FORCES_KEPT):
        self.kept = kept
        self.sound: dict = {}  # {(file, key): SoundGroup}
        # {(file, key): (the file's identity, {name: array}, whether checked)}, the last used last
        self.forces: dict = {}

    def check(self, f, parts, g, where: str, with_truth: bool = True) -> Shared:
        """The shared groups the shot ``g`` links to, each checked where its file is not the
        version found intact before: a shot read without its truth is not refused for
        damaged truth forces, which it does not read (InstrumentError, ``where`` first, for
        the rest). ``f``: the archive's master (or layout-2 file); ``parts``: the
        links.OpenParts the shot was read through."""
        linked: dict = {}
        scene, truth = None, None
        text = table_text(g)
        sealed = stored_rows(text)
        for key in sorted(links_below(sealed, "/shared/")):
            s = parts.group(f["shared"], key)  # its part opened directly, as the shot's is
            at = (s.file.filename, key)
            truth_here = with_truth and _links_to(sealed, "truth/forces", key, "forces")
            sound = self._sound(s, at, f"{where}: shared/{key}/", with_truth, truth_here)
            linked.update(sound.addresses)
            if _links_to(sealed, "scene_text", key, "scene_text"):
                scene = sound.texts
            if truth_here:
                truth = self._forces(s, at, sound.identity, f"{where}: shared/{key}/")
        return Shared(text, linked, scene, truth)

    def unchecked_truth(self, f, parts, g) -> dict | None:
        """The truth forces the shot ``g`` links to, for a read that skips the checksums:
        those kept for the version of their file that is there now, else read from it and
        kept as unchecked; None where its table names no shared truth (the caller reads the
        shot's own)."""
        sealed = stored_rows(table_text(g))
        for key in links_below(sealed, "/shared/"):
            if _links_to(sealed, "truth/forces", key, "forces"):
                s = parts.group(f["shared"], key)
                return self._forces(s, (s.file.filename, key), file_identity(s.file.filename))
        return None

    def _sound(self, s, at: tuple, where: str, with_truth: bool, truth_here: bool) -> SoundGroup:
        """The group ``s`` (at (file, key)), checked where its file is not the version found
        intact before; ``truth_here``: its forces are the shot's truth, read first (kept,
        where the group is intact) and their rows of the table taken from the values read."""
        identity = file_identity(at[0])
        known = self.sound.get(at)
        if known and known.identity == identity:
            return known
        forces: dict = {}
        if truth_here:
            with contextlib.suppress(Exception):  # damaged: the check below says what
                forces = truth_forces(s["forces"])
        problems = damage(s, {}, read=_every_row, known=_rows(forces))
        refused = problems if with_truth else [p for p in problems if not truth_item(p)]
        if refused:
            raise InstrumentError(f"{where}{refused[0]}")
        known = SoundGroup(identity, addresses(s), {k: s[k][()].decode() for k in ("scene_text", "settings") if k in s})
        if not problems:
            self.sound[at] = known
            if forces:
                self._keep(at, (identity, forces, True))
        return known

    def _forces(self, s, at: tuple, identity, where: str | None = None) -> dict:
        """The truth forces of the group ``s`` (at (file, key); the file's ``identity`` when it
        was checked, or now): read once per version of its file, the last ``kept`` groups'
        kept. A checked read (``where`` given, its error's start) takes only forces that were
        checked, and checks those it reads against the group's table (InstrumentError)."""
        checked = where is not None
        held = self.forces.pop(at, None)
        if held is None or held[0] is None or held[0] != identity or (checked and not held[2]):
            forces = truth_forces(s["forces"])
            if checked:
                rows = _rows(forces)
                problems = damage(s, {}, read=rows.__contains__, known=rows)
                if problems:
                    raise InstrumentError(f"{where}{problems[0]}")
            held = identity, forces, checked
        self._keep(at, held)
        return dict(held[1])

    def _keep(self, at: tuple, held: tuple):
        """Keep ``held`` as the forces of ``at``, the last used: those of the last ``kept`` groups."""
        self.forces.pop(at, None)
        self.forces[at] = held
        while len(self.forces) > self.kept:
            self.forces.pop(next(iter(self.forces)))


def truth_forces(forces) -> dict:
    """{name: array in N} of a truth's ``forces`` group (NXdata; its time axis left out),
    each array read-only: the reads of one scene's shots share them (SharedGroups). Each is
    read as the table of checksums reads it (values.member_value), so its row there is the
    digest of the value returned."""
    axis = forces.attrs["axes"][0]
    out = {k: member_value(forces, k) for k in forces if k != axis}
    for values in out.values():
        values.setflags(write=False)
    return out


def _rows(forces: dict) -> dict:
    """The rows of a shared group's table ({"forces/<name>": SHA-256}) of ``forces`` as read
    (truth_forces)."""
    return {f"forces/{name}": value_digest(values) for name, values in forces.items()}


def _every_row(key: str) -> bool:
    """damage()'s ``read``: every row of a shared group's table, each computed alone."""
    return True


def _links_to(sealed: dict, row: str, key: str, name: str) -> bool:
    """Whether the shot's sealed table says its ``row`` is a link to ``/shared/<key>/<name>``
    (in this file or, layouts 3 and 4, in another part)."""
    return str(sealed.get(row, "")).split(" in ")[0] == f"link:/shared/{key}/{name}"
