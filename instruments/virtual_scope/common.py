"""IEEE 488.2 common commands and the status, event and reply-form commands of a Tek scope
(TDS2000 and MDO3000 programmer manuals, "Status and Events", "Miscellaneous"):
``*IDN? *RST *CLS *OPC[?] *WAI *ESR? *ESE *SRE *PSC *STB? *TRG *TST?``, ``DESE ALLEv? EVENT?
EVMsg? EVQty? SYSTem:ERRor? BUSY? HEADer VERBose`` (DESE and *PSC: StatusModel). Every queue
read takes the event off the queue; ``ALLEv?`` takes them all (``0,"No events to report -
queue empty"`` when none). The event queries give Tek's unsigned codes (113 "Undefined
header"), ``SYSTem:ERRor?`` SCPI's (-113)."""
from __future__ import annotations

from ..scpi.engine import Call
from ..scpi.status import ScpiError


def register(tree, scope) -> None:
    """Add the common commands of ``scope`` (a VirtualScope) to a command tree."""
    status, acq = scope.status, scope.acq

    def wait(call: Call):
        scope.wait_idle(call.context)
        return "1"

    def register_byte(name: str):
        def write(call: Call):
            value = call.number()
            if not 0 <= value <= 255:
                raise ScpiError(-222, f"{call.header} {value:g}: allowed 0 to 255")
            setattr(status, name, round(value))
        return write

    def form_flag(name: str):
        def write(call: Call):
            call.only(1)
            setattr(scope.form, name, call.boolean())
        return write

    tree.add("*IDN", read=lambda c: scope.personality.idn, bare=True)
    tree.add("*RST", write=lambda c: scope.reset())
    tree.add("*CLS", write=lambda c: status.clear())
    tree.add("*OPC", write=lambda c: acq.opc(), read=wait, bare=True)
    tree.add("*WAI", write=lambda c: scope.wait_idle(c.context))
    tree.add("*ESR", read=lambda c: str(status.read_esr()), bare=True)
    tree.add("*ESE", write=register_byte("ese"), read=lambda c: str(status.ese), bare=True)
    tree.add("*SRE", write=register_byte("sre"), read=lambda c: str(status.sre), bare=True)
    tree.add("DESE", write=register_byte("dese"), read=lambda c: str(status.dese))
    tree.add("*PSC", write=lambda c: setattr(status, "psc", c.boolean()), read=lambda c: "1" if status.psc else "0",
             bare=True)
    tree.add("*STB", read=lambda c: str(status.status_byte(False)), bare=True)
    tree.add("*TRG", write=lambda c: acq.force())
    tree.add("*TST", read=lambda c: "0", bare=True)
    tree.add("ALLEv", read=lambda c: ",".join(_drain(status)))
    tree.add("EVENT", read=lambda c: str(status.next_event().tek_code))
    tree.add("EVQty", read=lambda c: str(len(status.events)))
    tree.add("EVMsg", read=lambda c: status.next_event().text())
    tree.add("SYSTem:ERRor", read=lambda c: _scpi_error(status.next_event()))
    tree.add("BUSY", read=lambda c: "1" if acq.awaiting else "0")
    tree.add("HEADer", write=form_flag("header"), read=lambda c: "1" if scope.form.header else "0")
    tree.add("VERBose", write=form_flag("verbose"), read=lambda c: "1" if scope.form.verbose else "0")


def _drain(status) -> list:
    events = [status.next_event().text() for _ in range(len(status.events))]
    return events or [status.next_event().text()]


def _scpi_error(event) -> str:
    """SYSTem:ERRor?'s form: ``0,"No error"`` when the queue is empty."""
    return '0,"No error"' if event.code == 0 else event.text(scpi=True)
