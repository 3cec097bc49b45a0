"""The measurement side's own error type (instruments never import the rig)."""


class InstrumentError(ValueError):
    """A bad setting or file: the message names the field, the value and what is allowed."""


def check(field: str, value, *, lo=None, hi=None, lo_closed=False, hi_closed=True, unit="",
          choices=None):
    """Validate one front-panel field; returns the value (floats as float)."""
    if choices is not None:
        if value not in choices:
            raise InstrumentError(f"{field} = {value!r}: allowed {', '.join(map(str, choices))}")
        return value
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InstrumentError(f"{field} = {value!r}: expected a number{' in ' + unit if unit else ''}") from None
    too_low = lo is not None and (x < lo if lo_closed else x <= lo)
    too_high = hi is not None and (x > hi if hi_closed else x >= hi)
    if too_low or too_high or x != x:
        lo_s = "" if lo is None else f"{lo:.6g} {'<=' if lo_closed else '<'} "
        hi_s = "" if hi is None else f" {'<=' if hi_closed else '<'} {hi:.6g}"
        raise InstrumentError(f"{field} = {value!r}: allowed {lo_s}{field.split('.')[-1]}{hi_s}"
                              f"{' (' + unit + ')' if unit else ''}")
    return x
