"""pyins.reference.abi against the built library: every enumerator of
pyins_core.h, name by name and value by value, both ways.

The header's enums are read from the header the binding loaded (its text)
and their enumerators from cffi's parse of it; nothing is copied here.
"""
import re

from pyins import native
from pyins.reference import abi

HEADER = native._locate()[1]["pyins_core.h"]


def test_every_header_enum_is_mirrored_with_the_same_names_and_values():
    enums = re.findall(r"enum\s+(pyins_\w+)\s*\{", HEADER)
    assert enums, "no enum found in pyins_core.h"
    assert sorted(abi.ENUMS) == sorted(enums)
    for enum in enums:
        header = dict(native.ffi.typeof(f"enum {enum}").relements)
        assert abi.ENUMS[enum] == header, enum


def test_every_enumerator_of_the_header_is_an_abi_name_and_back():
    lib_names = set(re.findall(r"\b(PYINS_[A-Z0-9_]+)\s*=", HEADER))   # pyins_core.h only
    abi_names = {n for n in dir(abi) if n.startswith("PYINS_")}
    assert abi_names == lib_names
    for name in sorted(lib_names):
        assert getattr(abi, name) == getattr(native.lib, name), name


def test_the_rejecting_statuses_are_the_ones_native_names():
    assert set(abi.SAMPLE_REJECTED) == set(native._SAMPLE_REJECTED)
