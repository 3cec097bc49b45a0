"""The scope's clock: ``DATE`` and ``TIMe`` (the manuals' miscellaneous group: the date
"yyyy-mm-dd" and the time "hh:mm:ss" of the instrument's clock, each settable with a quoted
string and answered as one). The clock is the host's, shifted by what a client set; *RST
leaves it, as it leaves a real scope's clock."""
from __future__ import annotations

import datetime as dt
import re

from ..scpi.status import ScpiError

DATE = re.compile(r"^(\d{4})-(\d{2})-(\d{2})$")
TIME = re.compile(r"^(\d{2}):(\d{2}):(\d{2})$")


def register(tree) -> None:
    """Add DATE and TIME to a command tree, on a clock of their own."""
    shift = [dt.timedelta(0)]

    def now() -> dt.datetime:
        return dt.datetime.now() + shift[0]

    def setter(pattern: re.Pattern, form: str, moved):
        def write(call):
            call.only(1)
            a = call.arg()
            m = pattern.match(a.text.strip()) if a.kind == "string" else None
            if m is None:
                raise ScpiError(-224, f"{call.header} {a.text[:40]!r}: allowed a quoted {form}")
            try:
                target = moved(now(), *map(int, m.groups()))
            except ValueError:  # a 30th of February, an hour 25
                raise ScpiError(-222, f"{call.header} {a.text[:40]!r}: not a {form} of the calendar") from None
            shift[0] += target - now()
        return write

    tree.add("DATE", write=setter(DATE, '"yyyy-mm-dd"', lambda t, y, mo, d: t.replace(year=y, month=mo, day=d)),
             read=lambda c: f'"{now():%Y-%m-%d}"')
    tree.add("TIMe", write=setter(TIME, '"hh:mm:ss"', lambda t, h, mi, s: t.replace(hour=h, minute=mi, second=s)),
             read=lambda c: f'"{now():%H:%M:%S}"')
