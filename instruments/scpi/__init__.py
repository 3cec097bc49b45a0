"""A generic SCPI engine (IEEE 488.2 and SCPI 1999): the parser (``parser.py``), numbers
with suffix units (``numbers.py``), definite-length blocks (``blocks.py``), the status model
and the event queue (``status.py``), the command tree (``tree.py``) and the execution of
one program message with its reply forms (``engine.py``). It knows no instrument."""
