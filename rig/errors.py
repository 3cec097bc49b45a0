"""The one exception type a user of the rig sees for a mistake in the input."""


class RigError(ValueError):
    """Bad input: the message names the field, the value and what is allowed."""


def invalid(field: str, value, allowed: str) -> RigError:
    """Build the standard message: ``field = value: allowed``."""
    return RigError(f"{field} = {value!r}: {allowed}")
