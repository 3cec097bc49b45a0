"""The old names Tektronix's example scripts use, given by today's libraries: ``import
visa`` (pyvisa's module before 1.12) and ``numpy.float`` (removed in numpy 1.24). The
test that runs the scripts (test_clients.py) puts this folder on PYTHONPATH and sets
PYVISA_LIBRARY=@py (pyvisa-py, the scripts name no VISA library) and MPLBACKEND=Agg (their
plots drawn off screen, ``show()`` returns at once). Nothing here stands in for the
instrument."""
import sys

import numpy
import pyvisa

numpy.float = float
sys.modules.setdefault("visa", pyvisa)
