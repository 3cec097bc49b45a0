"""Scope file formats: Tektronix ISF (binary) and Tektronix CSV, by file extension."""
from .isf import read_isf, write_isf
from .tek_csv import read_csv, write_csv

WRITERS = {"isf": write_isf, "csv": write_csv}
READERS = {".isf": read_isf, ".csv": read_csv}
