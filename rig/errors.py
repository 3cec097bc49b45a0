"""The one exception type a user of the rig sees for a mistake in the input."""


class RigError(ValueError):
    """Bad input: the message names the field, the value and what is allowed."""


class RigNote(UserWarning):
    """A note on how the rig read the input (a key read another way than its name says): a
    warning, shown once per distinct text; the command line prints it as one line ``note:
    ...`` on stderr."""


class Interrupted(RigError):
    """A run stopped by the user (Ctrl-C): the message says what it kept."""


def invalid(field: str, value, allowed: str) -> RigError:
    """Build the standard message: ``field = value: allowed``."""
    return RigError(f"{field} = {value!r}: {allowed}")


def lookup(registry: dict, name, field: str, kind: type):
    """registry[name], passing a ``kind`` instance through; a clear error otherwise."""
    if isinstance(name, kind):
        return name
    key = str(name).strip().lower()
    if key not in registry:
        raise invalid(field, name, f"known {field.split('.')[-1].lstrip('-')}s: {', '.join(sorted(registry))}")
    return registry[key]
