"""Waveform transfer (programmer manuals, "Waveform Transfer"
command group): ``DATa:SOUrce[:AVAILable?]/STARt/STOP/ENCdg/WIDth``, ``DATa INIT``, ``DATa?``,
the personality's preamble (``WFMPre?`` or ``WFMOutpre?``, whole and per field), ``CURVe?``,
and ``WAVFrm?`` (preamble;curve). The preamble's BYT_Nr, BIT_Nr, ENCdg, BN_Fmt and BYT_Or
are settable too, as the manuals give them: they set DATa:WIDth and DATa:ENCdg. A channel that
is off is 2244 "Source waveform is not active" for CURVe? (the preamble: see ``preamble``
below); ``CURVe?`` before the first record or after a failed shot is an execution error
(-200). Either way CURVe? answers at once with an empty block (``#10``), the event in the
queue, so that a client reads the error instead of waiting out its timeout."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..records import Preamble
from ..scpi.engine import Call, Fields, Word
from ..scpi.status import ScpiError
from .commands import CHANNEL_WORDS
from .manual import LETTERED
from .transfer import DataSelection, curve_bytes, preamble_fields, waveform_id

WAVEFORM_FIELDS = ("WFId", "NR_Pt", "PT_Fmt", "XINcr", "PT_Off", "XZEro", "XUNit", "YMUlt", "YZEro", "YOFf", "YUNit")
"""The preamble fields that describe one waveform (TDS2000 manual, WFMPre:<wfm>?), in its order."""


REFERENCE_FIELDS = ("PT_Fmt", "XINcr", "XUNit", "XZEro", "YMUlt", "YOFf", "YUNit", "YZEro")
"""The WFMPre fields whose set forms (TDS2000 manual) describe the reference waveform
DATa:DESTination names: -221 here, where no reference waveform is emulated."""


def reference(c: Call):
    """The set form of a REFERENCE_FIELDS field: -221, reference waveforms are not emulated."""
    raise ScpiError(-221, f"{c.header}: sets the preamble of the reference waveform DATa:DESTination names; "
                          f"reference waveforms are not emulated")


def source_waveform(scope, ch: str, header: str, *, off_too: bool = False):
    """(codes or None, Preamble, WFID) of channel ``ch``: the last record's, or where there
    is none yet (or the channel is off and ``off_too``) the preamble its settings give
    (codes None); a channel that is off is 2244 unless ``off_too``."""
    shown = ch in scope.shown
    if not shown and not off_too:
        raise ScpiError(2244, f"{ch} is off; {header}")
    shot = scope.acq.last
    if shown and shot is not None and ch in shot.record.waveforms:
        w = shot.record[ch]
        mode = "Sample" if w.preamble.waveform_id.endswith("Sample mode") else "Average"
        ex = w.preamble.extra
        return w.codes, w.preamble, waveform_id(ch, w.preamble, ex.get("coupling", "DC"),
                                                ex.get("volts_per_div", w.preamble.y_multiplier * 25), mode,
                                                scope.personality)
    s = scope.settings
    n, dt = s["scope.record_length"], s["scope.sample_interval"]
    vdiv = s[f"scope.channels.{ch}.volts_per_div"]
    pre = Preamble(points=n, x_increment=dt, x_zero=-s["scope.trigger.pre_trigger"] * n * dt,
                   trigger_index=round(s["scope.trigger.pre_trigger"] * n), y_multiplier=vdiv / 25,
                   y_offset=s[f"scope.channels.{ch}.position"] * 25, y_zero=s[f"scope.channels.{ch}.offset"])
    mode = "Sample" if s["scope.mode"] == "sample" else "Average"
    return None, pre, waveform_id(ch, pre, s[f"scope.channels.{ch}.coupling"], vdiv, mode, scope.personality)


def curve_answer(scope, header: str) -> tuple:
    """(CURVe?'s answer without its header, whether it holds the record): the last record's
    codes of DATa:SOUrce as DATa sets them (in NORMal, a shot that did not trigger leaves the
    last record); where there is none (no record yet, the last shot failed, the source is
    off) an empty answer (``#10``, or an
    empty line in ASCIi) with the reason in the queue, so that a client reads the error
    instead of waiting out its timeout."""
    empty = curve_bytes(np.zeros(0, np.int8), scope.data)
    if scope.data.sources:  # several sources at once: their blocks' layout is not the manuals'
        scope.status.post(-221, f"DATa:SOUrce {','.join(scope.data.sources)}: CURVe? sends one source at a time "
                                f"here (DATa:SOUrce {scope.data.source}); {header}")
        return empty, False
    try:
        codes, _, _ = source_waveform(scope, scope.data.source, header)
    except ScpiError as off:  # 2244: the source is off
        scope.status.post(off.code, off.detail)
        return empty, False
    if codes is None:
        why = (f"the last shot failed ({scope.acq.failure})" if scope.acq.failure else
               "no record yet; fire a shot (ACQuire:STATE ON, TRIGger FORCe or RIG:FIRE)")
        scope.status.post(-200, f"{scope.data.source} has no record: {why}; {header}")
        return empty, False
    return curve_bytes(codes, scope.data), True


def register(tree, scope) -> None:
    """Add the waveform commands of ``scope`` (a VirtualScope)."""
    p = scope.personality

    def data(**changes):
        scope.data = replace(scope.data, **changes)

    def point(c: Call) -> int:
        """A point number, clamped to 1 .. max_record_length as the scopes clamp it (scripts
        send ``DATa:STOP 1e10`` for "to the end")."""
        return min(max(round(c.number()), 1), scope.max_record_length)

    def width(c: Call):
        """DATa:WIDth and BYT_Nr: 1 or 2 bytes of integer codes, or (BYT_Nr 4, where the
        model sends floats) 4-byte floats."""
        set_width(c, 8)

    def set_width(c: Call, bits: int, floats: bool = False):
        """The bytes a point is sent in, from the argument in units of ``bits`` bits (8: BYT_Nr,
        DATa:WIDth; 1: BIT_Nr); ``floats``: 4 bytes are floats (the preamble's fields, on a
        model that sends them)."""
        w = c.number() * bits / 8
        if w == 4 and floats:
            scope.data = scope.data.formatted(floating=True)
        elif w in (1, 2):
            sel = scope.data.formatted(signed=True) if scope.data.floating else scope.data
            scope.data = replace(sel, width=int(w))
        else:
            allowed = [f"{8 * n // bits:d}" for n in ((1, 2, 4) if floats else (1, 2))]
            raise ScpiError(-222, f"{c.header} {c.arg().text}: allowed {', '.join(allowed[:-1])} or {allowed[-1]} "
                                  f"{'bytes' if bits == 8 else 'bits'} per point")

    def preamble(c: Call) -> Fields:
        """The whole preamble; of a channel that is off, a TDS answers its format fields
        only (BYT_NR to BYT_OR, TDS2000 manual, WFMPre?), an MDO or MSO every field from
        the channel's settings (qcodes' DPO7200xx driver reads XUNit of every channel)."""
        off = scope.data.source not in scope.shown
        _, pre, wfid = source_waveform(scope, scope.data.source, c.header, off_too=True)
        fields = preamble_fields(pre, scope.data, wfid, p)
        return Fields(fields.pairs[:5]) if off and p.name == "tds2000" else fields

    def preamble_field(name: str):
        def read(c: Call):
            pairs = dict(preamble(c).pairs)
            if name not in pairs:
                raise ScpiError(2244, f"{scope.data.source} is off; {c.header}")
            return pairs[name]
        return read

    def curve(c: Call) -> bytes:
        return curve_answer(scope, c.header)[0]

    def wavfrm(c: Call) -> bytes:
        """``WFMPre?;CURVe?`` in one reply, each part in the current reply form (with
        HEADer ON: ``:WFMPRE:BYT_NR 1;...;:CURVE #...``)."""
        engine, tree = scope.engine, scope.engine.tree
        return (engine.reply(preamble(c), tree.find((p.preamble.upper(),))) + b";"
                + engine.reply(curve(c), tree.find(("CURVE",))))

    def data_init(c: Call):
        c.word(("INIT",))
        scope.data = DataSelection(stop=scope.initial["scope.record_length"])

    destination = Word("REFA" if p.name in LETTERED else "REF1")  # where DATa:DESTination would write (no refs)
    tree.add("DATa", write=data_init, read=lambda c: Fields((
        ("DESTination", destination), ("ENCdg", Word(scope.data.encoding)), ("SOUrce", Word(scope.data.source)),
        ("STARt", str(scope.data.start)), ("STOP", str(scope.data.stop)), ("WIDth", str(scope.data.sent_width)))))

    def set_sources(c: Call):
        """DATa:SOUrce <wfm>[<,><wfm>] (the 4 Series' manual: a list, the first the source of
        the preamble and CURVe?); the TDS2000's and MDO3000's manuals take one source
        (``DATa:SOUrce {CH<x>|MATH|REF<x>|...}``): a list there is 108, "Parameter not allowed"."""
        names = [c.word(CHANNEL_WORDS, i) for i in range(max(len(c.args), 1) if p.source_list else 1)]
        data(source=names[0], sources=tuple(names) if len(names) > 1 else ())

    tree.add("DATa:SOUrce", write=set_sources,
             read=lambda c: ",".join(scope.data.sources) if scope.data.sources else Word(scope.data.source))
    tree.add("DATa:SOUrce:AVAILable", read=lambda c: ",".join(ch for ch in CHANNEL_WORDS if ch in scope.shown))
    tree.add("DATa:STARt", write=lambda c: data(start=point(c)), read=lambda c: str(scope.data.start))
    tree.add("DATa:STOP", write=lambda c: data(stop=point(c)), read=lambda c: str(scope.data.stop))
    tree.add("DATa:ENCdg", write=lambda c: setattr(scope, "data", scope.data.encoded(c.word(p.encodings))),
             read=lambda c: Word(scope.data.encoding))
    tree.add("DATa:WIDth", write=width, read=lambda c: str(scope.data.sent_width))  # 4 with floats, as BYT_NR
    tree.add(p.preamble, read=preamble)
    def set_format(c: Call):
        fmt = c.word(("RI", "RP", "FP") if p.floats else ("RI", "RP"))
        scope.data = scope.data.formatted(floating=True) if fmt == "FP" else scope.data.formatted(signed=fmt == "RI")

    def set_encoding(c: Call):
        """ENCdg's words as the model's manual prints them: ASCii or BINary; the TDS's ASC or BIN."""
        words = ("ASCIi", "BINary") if p.engineering else ("ASC", "BIN")
        scope.data = scope.data.encoded("ASCIi" if c.word(words) == words[0] else scope.data.binary)

    def bits(c: Call):
        """BIT_Nr 8 or 16: the bits a point is sent in, with BYT_Nr (the 4/5/6 Series way to
        ask for 2 bytes a point; it had been refused, the client reading 1-byte codes as 2)."""
        set_width(c, 1, p.floats)

    setters = {"BYT_Nr": lambda c: set_width(c, 8, p.floats), "BIT_Nr": bits, "ENCdg": set_encoding,
               "BN_Fmt": set_format,
               "BYT_Or": lambda c: setattr(scope, "data",
                                           scope.data.formatted(msb_first=c.word(("MSB", "LSB")) == "MSB"))}
    if p.name == "tds2000":  # its manual's set forms of the fields that describe a waveform write a reference one
        setters.update({name: reference for name in REFERENCE_FIELDS})
    for name in p.preamble_fields:
        tree.add(f"{p.preamble}:{name}", read=preamble_field(name), write=setters.get(name))
    def channel_preamble(c: Call) -> Fields:
        """``WFMPre:CH<x>?`` (TDS2000 manual; the legacy form of the DPO4000's and MDO3000's):
        the fields that describe channel x's waveform (WFID to YUNIT), whatever DATa:SOUrce
        is; a channel that is off is 2244."""
        ch = f"CH{c.suffix}"
        if ch not in CHANNEL_WORDS:
            raise ScpiError(-113, f"{c.header}: channels CH1 to CH4")
        _, pre, wfid = source_waveform(scope, ch, c.header)
        pairs = dict(preamble_fields(pre, scope.data, wfid, p).pairs)
        return Fields(tuple((name, pairs[name]) for name in WAVEFORM_FIELDS))

    def channel_field(name: str):
        return lambda c: dict(channel_preamble(c).pairs)[name]

    tree.add("WFMPre:CH<n>", read=channel_preamble)
    for name in WAVEFORM_FIELDS:
        tree.add(f"WFMPre:CH<n>:{name}", read=channel_field(name))
    if p.preamble != "WFMPre":  # the legacy WFMPre of the DPO4000 and MDO3000 manuals: WFMOutpre's fields
        tree.add("WFMPre", read=preamble)
        for name in p.preamble_fields:
            tree.add(f"WFMPre:{name}", read=preamble_field(name), write=setters.get(name))
    tree.add("CURVe", read=curve)
    tree.add("WAVFrm", read=wavfrm, bare=True)  # its parts carry their own headers
