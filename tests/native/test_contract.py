"""pyins.contract (the ABI's data contract without the library) against the
built library: the same objects re-exported by native, the status texts of
pyins_status_str, the record layouts, and the two engines' configurations:
the reference's defaults (reference/config.py) equal pyins_config_default
field by field, and what each instance resolves them to is the same (the C
instance's resolved configuration read out of its snapshot)."""
import numpy as np
import pytest

from pyins import contract, native, reference
from pyins.reference import abi, c_api, config

REEXPORTED = ("SAMPLE_DTYPE", "OUTPUT_DTYPE", "NAV_DTYPE", "CONFIG_FIELDS", "VERTICAL_MODES", "CoreError",
              "ConfigError", "SampleError", "SnapshotError", "PlantError", "make_samples")


@pytest.mark.parametrize("name", REEXPORTED)
def test_native_reexports_the_contracts_objects(name):
    assert getattr(native, name) is getattr(contract, name)


def test_the_record_layouts_are_the_librarys():
    for struct, dtype in (("pyins_sample", contract.SAMPLE_DTYPE), ("pyins_output", contract.OUTPUT_DTYPE),
                          ("pyins_nav", contract.NAV_DTYPE)):
        assert native._numpy_dtype(struct) == dtype
    assert contract.SAMPLE_DTYPE.itemsize == native.lib.pyins_sizeof_sample()
    assert contract.OUTPUT_DTYPE.itemsize == native.lib.pyins_sizeof_output()
    assert contract.NAV_DTYPE.itemsize == native.lib.pyins_sizeof_nav()
    assert contract.ffi.sizeof("pyins_config") == native.lib.pyins_sizeof_config()
    assert contract.CONFIG_FIELDS == tuple(name for name, _ in native.ffi.typeof("pyins_config").fields)


def test_every_status_text_is_the_librarys():
    codes = dict(native.ffi.typeof("enum pyins_status").relements)
    assert codes == contract.STATUSES
    assert set(abi.ENUMS["pyins_status"].values()) == set(codes.values())
    for code in [*codes.values(), -8, -9, -38, 5, 1000, -2**31]:
        want = native.status_str(code)
        assert contract.status_str(code) == want, code
        assert c_api.pyins_status_str(code) == want, code


def test_the_reference_engines_errors_are_caught_through_native():
    with pytest.raises(native.ConfigError) as info:
        reference.Firmware(lat_rad=2.0)
    assert info.value.status_name == "PYINS_E_CONFIG_LAT"
    with pytest.raises(native.SampleError):
        reference.Firmware().step([np.nan, 0.0, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(native.SnapshotError):
        reference.Firmware().restore(b"x" * 64)


def _struct_bytes(cfg):
    return bytes(contract.ffi.buffer(cfg))


def test_the_reference_defaults_are_pyins_config_default():
    c_default = native.make_config()                 # pyins_config_default
    ref_default = c_api.make_config()                # reference/config.py's config_default()
    mirror, c = c_api.config_from_struct(ref_default), c_api.config_from_struct(c_default)
    for name in contract.CONFIG_FIELDS:
        np.testing.assert_array_equal(np.asarray(mirror[name]), np.asarray(c[name]), err_msg=name)
    assert _struct_bytes(ref_default) == bytes(native.ffi.buffer(c_default))   # padding and all
    for name, value in config.config_default().items():
        if name != "index_steps":
            np.testing.assert_array_equal(np.asarray(value), np.asarray(c[name]), err_msg=name)


@pytest.mark.parametrize("fields", [
    {"nope": 1}, {"vel_n_mps": [1.0, 2.0]}, {"tick_hz": "x"}, {"tick_hz": 2**40}, {"vertical_mode": "up"},
    {"index_steps": [(1, 1, 1.0)] * 9}, {"index_steps": [(1, 1)]}, {"lever_b_m": "abc"},
])
def test_the_reference_refuses_what_make_config_refuses_with_the_same_message(fields):
    with pytest.raises(ValueError) as c_info:
        native.make_config(fields)
    with pytest.raises(ValueError) as ref_info:
        reference.Firmware(fields)
    assert str(ref_info.value) == str(c_info.value)


# The C core does not expose its resolved configuration (no hook in
# pyins_core_testing.h); the instance holds it (Firmware::cfg_), and its
# snapshot holds the instance's bytes. A configuration with marker values in
# the fields config_resolved leaves as they are (lat .. table angle, just
# after tick_hz and vertical_mode) finds it there; the struct there is read
# back and held against the reference instance's resolved configuration.
MARKERS = dict(lat_rad=0.612345678901, lon_rad=-1.98765432101, height_m=12.3456789,
               vel_n_mps=[0.123, -0.456, 0.0], euler_b_rad=[0.0123, -0.0234, 2.345], table_angle_rad=0.4567)
CASES = {
    "defaults": {},
    "200 Hz": dict(tick_hz=200),
    "moving base": dict(fine_states=12, fine_ticks=1000),
    "coarse then fine": dict(coarse_ticks=6000, fine_ticks=1000),
    "coarse, one sigma set": dict(coarse_ticks=6000, fine_sigma0_att_rad=[1e-3, 0.0, 0.0]),
    "single fwd/rev": dict(index_scheme=abi.PYINS_INDEX_SINGLE_FWD_REV),
    "four position": dict(index_scheme=abi.PYINS_INDEX_FOUR_POSITION, tick_hz=50),
    "custom": dict(index_scheme=abi.PYINS_INDEX_CUSTOM, index_n_steps=2, index_rate_rad_s=0.1,
                   index_accel_rad_s2=0.2, index_steps=[(100, 1, np.pi), (100, 1, -np.pi)]),
}


def _resolved_in_snapshot(fw):
    blob = fw.snapshot()
    marker = contract.ffi.new("pyins_config *")
    contract.set_config_fields(marker, MARKERS)
    start, end = contract.ffi.offsetof("pyins_config", "lat_rad"), contract.ffi.offsetof(
        "pyins_config", "coarse_ticks")
    key = _struct_bytes(marker)[start:end]
    at = blob.find(key)
    assert at >= 0 and blob.find(key, at + 1) < 0, "the marker fields are not once in the snapshot"
    size = contract.ffi.sizeof("pyins_config")
    raw = bytearray(blob[at - start: at - start + size])
    return c_api.config_from_struct(contract.ffi.from_buffer("pyins_config *", raw))


@pytest.mark.parametrize("case", CASES)
def test_the_resolved_configuration_is_the_cores(case):
    fields = {**MARKERS, **CASES[case]}
    c = _resolved_in_snapshot(native.Firmware(fields))
    ref = reference.Firmware(fields)
    mirror = ref.instance.cfg                               # what the mirror's instance runs with
    assert sorted(mirror) == sorted(c)
    for name in contract.CONFIG_FIELDS:
        want = [tuple(s) for s in c[name]] if name == "index_steps" else np.asarray(c[name])
        got = ([tuple(s) for s in mirror[name]] + [(0, 0, 0.0)] * 8)[:8] if name == "index_steps" \
            else np.asarray(mirror[name])
        np.testing.assert_array_equal(got, want, err_msg=f"{case}: {name}")
    # and the resolution alone (config_resolved), before the instance's coarse rule
    resolved = config.config_resolved(c_api.config_from_struct(c_api.make_config(fields)))
    if not fields.get("coarse_ticks"):
        for name in contract.CONFIG_FIELDS:
            if name != "index_steps":
                np.testing.assert_array_equal(np.asarray(resolved[name]), np.asarray(c[name]),
                                              err_msg=f"{case}: {name}")
    assert ref.config == native.Firmware(fields).config
