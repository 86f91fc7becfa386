"""The C ABI's named numbers: statuses, enums and bit flags of
``csrc/include/pyins_core.h``, under the header's own names.

One entry per enumerator of the header, in the header's order, with its
pinned value; tests/native/test_abi_names.py checks every name and value
against the built library's header (parsed by cffi), both ways. The mirror's
modules read their enums from here (or name them as their C++ twins do and
say which header value they are).
"""

# --- enum pyins_status: 0 success, negative rejected, positive a notice -----
PYINS_OK = 0
PYINS_E_NULL = -1
PYINS_E_MISALIGNED = -2
PYINS_E_MEM_TOO_SMALL = -3
PYINS_E_NOT_INIT = -4
PYINS_E_SAMPLE_NONFINITE = -5
PYINS_E_BAD_ARG = -6
PYINS_E_BUFFER_TOO_SMALL = -7
PYINS_E_CONFIG_RATE = -10
PYINS_E_CONFIG_LAT = -11
PYINS_E_CONFIG_LON = -12
PYINS_E_CONFIG_HEIGHT = -13
PYINS_E_CONFIG_VEL = -14
PYINS_E_CONFIG_ATT = -15
PYINS_E_CONFIG_MODE = -16
PYINS_E_CONFIG_ALIGN_RATIO = -17
PYINS_E_CONFIG_ALIGN_EARLY = -18
PYINS_E_CONFIG_ALIGN_LONG = -19
PYINS_E_CONFIG_ALIGN_TICKS = -20
PYINS_E_CONFIG_FINE = -21
PYINS_E_CONFIG_NOISE = -22
PYINS_E_CONFIG_INDEX_SCHEME = -23
PYINS_E_CONFIG_INDEX_EMPTY = -24
PYINS_E_CONFIG_INDEX_RATE = -25
PYINS_E_CONFIG_INDEX_DELTA = -26
PYINS_E_CONFIG_INDEX_STEP = -27
PYINS_E_SNAPSHOT_SIZE = -28
PYINS_E_SNAPSHOT_VERSION = -29
PYINS_E_SNAPSHOT_CORRUPT = -30
PYINS_E_SAMPLE_SATURATED = -31
PYINS_E_CONFIG_SATURATION = -32
PYINS_E_CONFIG_SEQ = -33
PYINS_E_CONFIG_INDEX_SUMS = -34
PYINS_E_CONFIG_LEVER = -35
PYINS_E_CONFIG_COARSE_METHOD = -36
PYINS_E_CONFIG_INTEGRITY = -37
PYINS_E_CONFIG_NAV = -38
PYINS_E_REF_KIND = -39
PYINS_E_REF_VALUE = -40
PYINS_E_REF_ORDER = -41
PYINS_E_REF_FUTURE = -42
PYINS_E_REF_FULL = -43
PYINS_E_REF_UNUSED = -44
PYINS_W_SEQ_GAP = 1          # notices: the sample was handled (docs/core.md)
PYINS_W_SEQ_REPEAT = 2
PYINS_W_SEQ_LOST = 3
PYINS_W_ENCODER_JUMP = 4

# --- enum pyins_index_scheme ------------------------------------------------
PYINS_INDEX_NONE = 0
PYINS_INDEX_SINGLE_FWD_REV = 1
PYINS_INDEX_TWO_POSITION = 2
PYINS_INDEX_FOUR_POSITION = 3
PYINS_INDEX_FLEXIBLE_TWO = 4
PYINS_INDEX_CUSTOM = 5
PYINS_INDEX_FLEXIBLE_DERIVED = 6
PYINS_INDEX_HEADING_ISOLATION = 7

# --- enum pyins_index_sums --------------------------------------------------
PYINS_INDEX_SUMS_STOPS = 0
PYINS_INDEX_SUMS_ALL = 1

# --- enum pyins_index_kind --------------------------------------------------
PYINS_INDEX_FIXED = 1
PYINS_INDEX_FLEX_COS = 2
PYINS_INDEX_FLEX_SIN = 3

# --- enum pyins_index_state -------------------------------------------------
PYINS_INDEX_IDLE = 0
PYINS_INDEX_STOP = 1
PYINS_INDEX_MOVE = 2
PYINS_INDEX_FAULT = 3

# --- enum pyins_coarse_method -----------------------------------------------
PYINS_COARSE_TRIAD = 0
PYINS_COARSE_FIT = 1
PYINS_COARSE_EQ8 = 2
PYINS_COARSE_FIT_VEL = 3

# --- enum pyins_fine_correction ---------------------------------------------
PYINS_FINE_FEEDBACK = 0
PYINS_FINE_OPEN_LOOP = 1

# --- enum pyins_fine_noise --------------------------------------------------
PYINS_FINE_NOISE_MEASURED = 0
PYINS_FINE_NOISE_CONFIGURED = 1

# --- enum pyins_fault_flag: sticky bits of pyins_output.fault_flags ---------
PYINS_FAULT_KF_NOT_PD = 1
PYINS_FAULT_ALIGN_RESTARTED = 2
PYINS_FAULT_SAMPLE_NONFINITE = 4
PYINS_FAULT_SAMPLE_SATURATED = 8
PYINS_FAULT_SEQ_GAP = 16
PYINS_FAULT_SEQ_REPEAT = 32
PYINS_FAULT_SEQ_LOST = 64
PYINS_FAULT_ENCODER_JUMP = 128
PYINS_FAULT_ALIGN_INCONSISTENT = 256
PYINS_FAULT_COARSE_UNSETTLED = 512
PYINS_FAULT_REF_REJECTED = 1024

# --- enum pyins_nav_mode ----------------------------------------------------
PYINS_NAV_AUTO = 0
PYINS_NAV_UNDAMPED = 1
PYINS_NAV_DAMPED = 2
PYINS_NAV_INTEGRATED = 3

# --- enum pyins_ref_kind ----------------------------------------------------
PYINS_REF_GNSS_POS = 1
PYINS_REF_GNSS_VEL = 2
PYINS_REF_SPEED_LOG = 3
PYINS_REF_DVL = 4
PYINS_REF_ZERO_VEL = 5

# --- enum pyins_seq_mode ----------------------------------------------------
PYINS_SEQ_OFF = 0
PYINS_SEQ_CHECK = 1

# --- enum pyins_mode --------------------------------------------------------
PYINS_MODE_IDLE = 0
PYINS_MODE_COARSE_ALIGN = 1
PYINS_MODE_FINE_ALIGN = 2
PYINS_MODE_NAVIGATE = 3

# --- enum pyins_state_flag: bits of pyins_output.state_flags ----------------
PYINS_STATE_ATT_VALID = 1
PYINS_STATE_POS_AIDED = 2

# --- enum pyins_vertical_mode -----------------------------------------------
PYINS_VERTICAL_HOLD = 0
PYINS_VERTICAL_FREE = 1

#: Every name above, by enum of the header (the test walks this table).
ENUMS = {
    enum: {name: value for name, value in globals().items()
           if name.startswith("PYINS_") and name in _names}
    for enum, _names in (
        ("pyins_status", [n for n in dir() if n.startswith(("PYINS_OK", "PYINS_E_", "PYINS_W_"))]),
        ("pyins_index_scheme", ["PYINS_INDEX_NONE", "PYINS_INDEX_SINGLE_FWD_REV", "PYINS_INDEX_TWO_POSITION",
                                "PYINS_INDEX_FOUR_POSITION", "PYINS_INDEX_FLEXIBLE_TWO", "PYINS_INDEX_CUSTOM",
                                "PYINS_INDEX_FLEXIBLE_DERIVED", "PYINS_INDEX_HEADING_ISOLATION"]),
        ("pyins_index_sums", ["PYINS_INDEX_SUMS_STOPS", "PYINS_INDEX_SUMS_ALL"]),
        ("pyins_index_kind", ["PYINS_INDEX_FIXED", "PYINS_INDEX_FLEX_COS", "PYINS_INDEX_FLEX_SIN"]),
        ("pyins_index_state", ["PYINS_INDEX_IDLE", "PYINS_INDEX_STOP", "PYINS_INDEX_MOVE",
                               "PYINS_INDEX_FAULT"]),
        ("pyins_coarse_method", ["PYINS_COARSE_TRIAD", "PYINS_COARSE_FIT", "PYINS_COARSE_EQ8",
                                 "PYINS_COARSE_FIT_VEL"]),
        ("pyins_fine_correction", ["PYINS_FINE_FEEDBACK", "PYINS_FINE_OPEN_LOOP"]),
        ("pyins_fine_noise", ["PYINS_FINE_NOISE_MEASURED", "PYINS_FINE_NOISE_CONFIGURED"]),
        ("pyins_fault_flag", [n for n in dir() if n.startswith("PYINS_FAULT_")]),
        ("pyins_seq_mode", ["PYINS_SEQ_OFF", "PYINS_SEQ_CHECK"]),
        ("pyins_mode", [n for n in dir() if n.startswith("PYINS_MODE_")]),
        ("pyins_nav_mode", ["PYINS_NAV_AUTO", "PYINS_NAV_UNDAMPED", "PYINS_NAV_DAMPED", "PYINS_NAV_INTEGRATED"]),
        ("pyins_ref_kind", [n for n in dir() if n.startswith("PYINS_REF_")]),
        ("pyins_state_flag", ["PYINS_STATE_ATT_VALID", "PYINS_STATE_POS_AIDED"]),
        ("pyins_vertical_mode", ["PYINS_VERTICAL_HOLD", "PYINS_VERTICAL_FREE"]),
    )
}

#: Statuses that reject a sample (the state is unchanged but for the fault
#: bits and counters; a batch stops there).
SAMPLE_REJECTED = (PYINS_E_SAMPLE_NONFINITE, PYINS_E_SAMPLE_SATURATED)


def fault_names(flags):
    """The names of the PYINS_FAULT_* bits set in ``flags``, without the
    prefix, lowest bit first (for messages and reports)."""
    bits = sorted((v, k[len("PYINS_FAULT_"):]) for k, v in globals().items()
                  if k.startswith("PYINS_FAULT_") and isinstance(v, int) and v)
    return [name for bit, name in bits if int(flags) & bit]
