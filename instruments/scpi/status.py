"""The IEEE 488.2 status model and the event queue of a Tektronix scope.

Standard event status register (IEEE 488.2 11.5.1): OPC (bit 0), RQC, QYE, DDE, EXE, CME,
URQ, PON (bit 7); the status byte (11.2): MAV (bit 4, a reply waits), ESB (bit 5, ESR & ESE),
MSS (bit 6, STB & SRE). Events carry the codes and messages of the Tektronix programmer
manuals (e.g. TDS200/TDS1000/TDS2000 Programmer Manual 071-1075, "Status and Events"):
the SCPI events (kept with SCPI's negative codes, which ``SYSTem:ERRor?`` answers; Tek's
event queries give them unsigned, see ``Event.tek_code``), and Tek's own four-digit
execution codes (2244 "Source waveform is not active"). When the queue is full its last
entry becomes -350 "Queue overflow"."""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

OPC, RQC, QYE, DDE, EXE, CME, URQ, PON = (1 << bit for bit in range(8))
MAV, ESB, MSS = 1 << 4, 1 << 5, 1 << 6

MESSAGES = {
    0: "No events to report - queue empty",
    1: "No events to report - new events pending *ESR?",
    -100: "Command error", -101: "Invalid character", -102: "Syntax error",
    -103: "Invalid separator", -104: "Data type error", -108: "Parameter not allowed",
    -109: "Missing parameter", -113: "Undefined header", -120: "Numeric data error",
    -131: "Invalid suffix", -141: "Invalid character data", -150: "String data error",
    -160: "Block data error", -200: "Execution error", -221: "Settings conflict",
    -222: "Data out of range", -224: "Illegal parameter value", -350: "Queue overflow",
    -363: "Input buffer overrun", -410: "Query INTERRUPTED", -420: "Query UNTERMINATED",
    2202: "Measurement error, No period found", 2209: "Measurement error, No second Mid Ref crossing",
    2211: "Measurement error, No backwards Mid Ref crossing", 2212: "Measurement error, No negative crossing",
    2213: "Measurement error, No positive crossing",
    2225: "Measurement error, No waveform to measure",
    2244: "Source waveform is not active",
}
QUEUE_SIZE = 32  # events kept; a Tek scope keeps 20 to 32
DETAIL_CHARS = 1000  # an event's detail is kept whole to this length (the rig's refusals run to ~300 characters)


class ScpiError(Exception):
    """An event a command raises: its code (a key of MESSAGES) and what it concerned."""

    def __init__(self, code: int, detail: str = "") -> None:
        super().__init__(f"{code}, {MESSAGES.get(code, 'Error')}; {detail}")
        self.code = code
        self.detail = detail


def esr_bit(code: int) -> int:
    """The ESR bit an event code sets: -1xx CME, -2xx and 2xxx EXE, -3xx DDE, -4xx QYE."""
    c = abs(code)
    if 100 <= c < 200:
        return CME
    if 200 <= c < 300 or 2000 <= c < 3000:
        return EXE
    if 300 <= c < 400:
        return DDE
    if 400 <= c < 500:
        return QYE
    return 0


@dataclass(frozen=True)
class Event:
    """One entry of the event queue."""

    code: int
    detail: str = ""

    @property
    def tek_code(self) -> int:
        """The code as ``EVENT?``, ``EVMsg?`` and ``ALLEv?`` give it: Tek's event tables
        number the SCPI events without their sign (113 "Undefined header", 222 "Data out of
        range", 350 "Queue overflow"); ``SYSTem:ERRor?`` gives SCPI's negative code."""
        return abs(self.code)

    def text(self, scpi: bool = False) -> str:
        """``<code>,"<message>; <detail>"`` (quotes in the detail doubled): the code as Tek's
        event queries give it (``tek_code``), or with ``scpi`` as SYSTem:ERRor? does."""
        said = MESSAGES.get(self.code, "Error") + (f"; {self.detail}" if self.detail else "")
        return f'{self.code if scpi else self.tek_code},"{said.replace(chr(34), chr(34) * 2)}"'


class StatusModel:
    """ESR, ESE, SRE, DESER and the event queue of one instrument (not thread-safe: its owner
    serialises access). It starts as a Tek scope powers on with ``*PSC`` 1 (the MDO3000 and
    4 Series manuals, *PSC: "the DESER register is set to 255 and the SRER and ESER registers
    are set to 0 at power-on"), the ESR with PON set. ``psc`` is that flag, kept and answered:
    nothing here outlives the instrument, so each start is a power-on with it true.

    DESER (``DESE``): "the mask that determines whether events are reported to the Standard
    Event Status Register (SESR), and entered into the Event Queue" (the manuals, DESE): an
    event whose ESR bit it clears neither sets that bit nor is queued. ``*CLS`` and ``*RST``
    leave the enable registers (ESER, SRER, DESER) as they are (IEEE 488.2 10.3, 10.32)."""

    def __init__(self, capacity: int = QUEUE_SIZE) -> None:
        self.dese = 0xFF
        self.ese = 0
        self.sre = 0
        self.psc = True
        self.esr = PON
        self.capacity = capacity
        self.events: deque[Event] = deque()

    def set_bits(self, bits: int) -> None:
        """Set ESR bits (OPC when an operation completes), those DESER lets through."""
        self.esr |= bits & self.dese

    def post(self, code: int, detail: str = "") -> None:
        """Queue an event and set its ESR bit, unless DESER masks that bit (then neither);
        a full queue's last entry becomes -350. An event of no ESR bit is always queued."""
        bit = esr_bit(code)
        if bit and not bit & self.dese:
            return
        self.esr |= bit
        if len(self.events) >= self.capacity:
            self.events[-1] = Event(-350)
        elif len(self.events) == self.capacity - 1:
            self.events.append(Event(-350))
        else:
            self.events.append(Event(code, detail[:DETAIL_CHARS]))

    def next_event(self) -> Event:
        """The oldest event, removed (``Event(0)`` when none)."""
        return self.events.popleft() if self.events else Event(0)

    def read_esr(self) -> int:
        """*ESR?: the register's value, then cleared."""
        value, self.esr = self.esr, 0
        return value

    def clear(self) -> None:
        """*CLS: the event queue and the ESR cleared."""
        self.events.clear()
        self.esr = 0

    def status_byte(self, message_available: bool) -> int:
        """*STB?: MAV, ESB and MSS (STB & SRE)."""
        stb = (MAV if message_available else 0) | (ESB if self.esr & self.ese else 0)
        return stb | (MSS if stb & self.sre & ~MSS else 0)
