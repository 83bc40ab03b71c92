# ctest-timeout: 300
# ctest-cost: 10
"""A catalogue of wrong or hostile scenario files, meshes and command lines (the issue's
acceptance list: "all exit 2 or 3 with the key or entity named, none exit 1 or crash, none
allocate more than 1 GB before refusing").

Each case builds its input in a scratch directory of its own, runs one crater command and
asserts, in a subTest named after the case:
  - the command ends within its timeout (a hang is a failure; the child is then killed);
  - its exit code is the expected one (2: bad input, 3: numerical failure), never 1, never a
    signal;
  - stderr holds no crash marker and names the key, entity or file (every needle of the case; a
    tuple of needles means one of them);
  - its peak resident set size (os.wait4's ru_maxrss of that very child, sampled as well from
    /proc while it runs) stays below 1 GiB. (ru_maxrss starts from the high-water mark of the
    process that forked it, this test's own ~20 MB: the big inputs are written in chunks.) A
    child past 1.25 GiB is killed: it has failed already, and the machine is shared.

tests/scenarios/test_bad_scenarios.py covers one problem per checked-in file; this catalogue is
about what a file cannot hold or what a careless or hostile user feeds the program: garbage,
huge or deeply nested files, special files, non-finite and absurd numbers, absurd counts, broken
meshes and checkpoints, a bad command line. A table of every case (exit code, peak memory,
time) is printed to stderr.

Environment (set by CMake): CRATER_BIN, CRATER_SOURCE_DIR, CRATER_TEST_TMP.
"""
import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

from crater_test import BIN, SOURCE_DIR, TMP
from scenario_blocks import (AIR, SAND, STEEL, box, compose_scenario, disk, domain, material, part,
                             scenario_text)

GIB = 1 << 30
MEMORY_LIMIT = GIB            # what a refusal may use at most (peak RSS)
KILL_RSS = 5 * GIB // 4       # the watchdog stops a child past this (it has failed already)
DEFAULT_TIMEOUT = 30          # [s] a hang is a failure (a refusal takes milliseconds)
HANG_TIMEOUT = 15             # [s] cases that hang when the program blocks (FIFOs, endless runs)

DEMO_PATH = SOURCE_DIR / "scenarios" / "demo.toml"
DEMO = DEMO_PATH.read_text()
PLATE_MSH = (SOURCE_DIR / "tests" / "data" / "meshes" / "plate_2x1.msh").read_text()

CRASH_MARKERS = (
    "Traceback (most recent call last)",
    "terminate called",
    "AddressSanitizer",
    "LeakSanitizer",
    "UndefinedBehaviorSanitizer",
    "runtime error:",
    "Segmentation fault",
    "core dumped",
    "Assertion",
    "std::bad_alloc",
)


# ---------------------------------------------------------------------------------------------
# Input builders. Each takes the case's scratch directory and returns the command's arguments.
# ---------------------------------------------------------------------------------------------

def write(d, name, *pieces):
    """Writes the pieces (str, bytes, or iterables of them, written one at a time so that this
    process stays small: a child's ru_maxrss starts from its parent's high-water mark) to d/name."""
    p = d / name
    with open(p, "wb") as f:
        for piece in pieces:
            for chunk in ([piece] if isinstance(piece, (str, bytes)) else piece):
                f.write(chunk.encode() if isinstance(chunk, str) else chunk)
    return p


def repeat(text, times, per_chunk=1 << 16):
    """text repeated `times` times, as chunks."""
    while times > 0:
        n = min(times, per_chunk)
        yield text * n
        times -= n


def demo_with(old, new, count=1):
    """The demo scenario with `old` replaced by `new` (which must be there)."""
    if DEMO.count(old) < 1:
        raise AssertionError(f"the demo no longer holds {old!r}")
    return DEMO.replace(old, new, count)


def sets(*overrides):
    out = []
    for o in overrides:
        out += ["--set", o]
    return out


def run_args(d, scenario, *extra):
    return ["run", scenario, "--out", d / "out", "--quiet", *extra]


def second_part(name, x):
    """A [[parts]] entry to append to the demo: a TNT disk of radius 0.1 m centred at (x, 0)."""
    return "\n" + scenario_text({"parts": [part(name, "sph", "tnt", 0.005, disk([x, 0.0], 0.1))]})


# A [[materials]] entry to append to the demo: a second material named "tnt".
SECOND_MATERIAL = "\n" + scenario_text({"materials": [material(AIR, name="tnt", rho0_kg_m3=1.2)]})


def mesh_scenario(mesh, **fem):
    """A 2D steel plate read from the mesh file `mesh` (more [parts.fem] keys in `fem`)."""
    return scenario_text(compose_scenario(
        "hostile-mesh", 2, 1e-5, domain=domain([-0.5, -0.5], [2.5, 1.5]), materials=[STEEL],
        parts=[part("plate", "fem", "steel", fem={"mesh_file": mesh, **fem})]))


def fem_box(spacing):
    """A 2D steel plate, 0.2 m x 0.02 m, meshed by the structured generator at `spacing`."""
    return scenario_text(compose_scenario(
        "hostile-fem-box", 2, 1e-5, domain=domain([0.0, 0.0], [0.2, 0.02]), materials=[STEEL],
        parts=[part("plate", "fem", "steel", spacing, box([0.0, 0.0], [0.2, 0.02]))]))


def dem_box(radius, spacing=0.0101, packing=None):
    """A 2D box of sand grains of one radius, on a lattice of pitch `spacing` or packed by
    `packing` ([parts.packing])."""
    return scenario_text(compose_scenario(
        "hostile-dem-box", 2, 1e-3,
        domain=domain([0.0, 0.0], [0.2, 0.3], gravity=[0.0, -9.81]), materials=[SAND],
        parts=[part("sand", "dem", "sand", spacing, box([0.0, 0.0], [0.2, 0.2]),
                    dem={"radius_min_m": radius, "radius_max_m": radius,
                         "walls": ["left", "right", "bottom"]},
                    packing=packing)]))


def mesh_case(mesh_text_or_bytes, mesh_name="plate.msh", command="check"):
    def build(d):
        write(d, mesh_name, mesh_text_or_bytes)
        scen = write(d, "mesh.toml", mesh_scenario(mesh_name))
        return run_args(d, scen) if command == "run" else ["check", scen]
    return build


def mesh_edit(edit):
    """plate_2x1.msh with its lines passed through edit(lines) -> lines."""
    return "\n".join(edit(PLATE_MSH.split("\n")))


def replace_line(old, new):
    def edit(lines):
        k = lines.index(old)
        return lines[:k] + [new] + lines[k + 1:]
    return edit


def after_header(section, new_header):
    """Replaces the count line that follows `section` (e.g. '$Elements')."""
    def edit(lines):
        k = lines.index(section)
        return lines[:k + 1] + [new_header] + lines[k + 2:]
    return edit


def element_with_missing_node(lines):
    k = lines.index("$Elements") + 3          # header, block header, first element
    fields = lines[k].split()
    fields[1] = "77777"
    return lines[:k] + [" ".join(fields)] + lines[k + 1:]


def garbage(n, seed):
    rng = random.Random(seed)
    return bytes(rng.getrandbits(8) for _ in range(n))


def make_fifo(d, name):
    p = d / name
    os.mkfifo(p)
    return p


def make_checkpoint(d):
    """A real checkpoint of a short demo run (every step checkpointed); returns its path."""
    out = d / "source_run"
    proc = subprocess.run([BIN, "run", DEMO_PATH, "--out", out, "--quiet", "--threads", "1",
                           *sets(*CHECKPOINT_SETS)],
                          capture_output=True, text=True, errors="replace", timeout=120)
    if proc.returncode != 0:
        raise AssertionError(f"could not make a checkpoint to damage: {proc.stderr}")
    cks = sorted((out / "checkpoints").glob("*.ckpt"))
    if not cks:
        raise AssertionError(f"the run wrote no checkpoint in {out / 'checkpoints'}")
    return cks[-1]


def truncated_checkpoint(d):
    ck = make_checkpoint(d)
    data = ck.read_bytes()
    ck.write_bytes(data[: len(data) // 3])
    return ["run", DEMO_PATH, "--restart", ck, "--out", d / "out", "--quiet"]


def fnv1a(data):
    """The checkpoint checksum (src/core/hash.hpp)."""
    h = 0xcbf29ce484222325
    for c in data:
        h = ((h ^ c) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


CHECKPOINT_SETS = ("scenario.end_time_s=3e-6", "output.checkpoint_every_steps=2")


def forged_checkpoint(edit):
    """A checkpoint of the demo whose payload edit(bytearray) changed, with header size and
    checksum made to match: the damage is found only by reading the state."""
    def build(d):
        ck = make_checkpoint(d)
        header, payload = ck.read_bytes().split(b"\n", 1)
        payload = bytearray(payload)
        edit(payload)
        header = header.split(b" bytes=")[0] + b" bytes=%d checksum=%016x" % (
            len(payload), fnv1a(payload))
        forged = write(d, "forged.ckpt", header + b"\n" + payload)
        return ["run", DEMO_PATH, "--restart", forged, "--out", d / "out", "--quiet",
                "--threads", "1", *sets(*CHECKPOINT_SETS)]
    return build


def huge_string_length(payload):
    payload[0:4] = b"\xff\xff\xff\xff"            # the length of the payload's first string


def huge_part_count(payload):
    k = payload.index(b"\x05\x00\x00\x00parts") + 9  # the count that follows "parts"
    payload[k:k + 8] = (10**18).to_bytes(8, "little")


def sparse_checkpoint(d):
    """A 2 GiB checkpoint of zeros (a sparse file) whose header says so (wrong checksum)."""
    ck = d / "checkpoints" / "step_000000000006.ckpt"
    ck.parent.mkdir()
    size = 2 * GIB
    with open(ck, "wb") as f:
        f.write(b"crater checkpoint v3 dim=2 scenario=6fd4bc45eca26dcc step=6 "
                b"time=0x1.4e8dcb620cf28p-19 bytes=%d checksum=0000000000000000\n" % size)
        f.truncate(size)
    return ["run", DEMO_PATH, "--restart", ck, "--out", d / "out", "--quiet"]


def resume_with_fifo_checkpoint(d):
    (d / "run" / "checkpoints").mkdir(parents=True)
    make_fifo(d / "run" / "checkpoints", "step_000000000009.ckpt")
    return ["run", DEMO_PATH, "--resume", d / "run", "--quiet"]


def resume_with_command(edit):
    """--resume of a real run directory whose crater-command.toml edit(text) changed."""
    def build(d):
        ck = make_checkpoint(d)
        run = ck.parent.parent
        cmd = run / "crater-command.toml"
        cmd.write_text(edit(cmd.read_text()))
        return ["run", "--resume", run, "--quiet"]
    return build


def command_threads(value):
    def edit(text):
        lines = [f"threads = {value}" if line.startswith("threads =") else line
                 for line in text.splitlines()]
        if lines == text.splitlines():
            raise AssertionError(f"no 'threads =' line in crater-command.toml:\n{text}")
        return "\n".join(lines) + "\n"
    return edit


def many_overlapping_parts(n):
    """The demo plus n identical small parts at one place: every pair overlaps."""
    yield DEMO
    part = ('[[parts]]\nname = "p{i}"\nmethod = "sph"\nmaterial = "tnt"\nspacing_m = 0.001\n'
            'region = {{ type = "disk", center_m = [0.5, 0.5], radius_m = 0.004 }}\n')
    for start in range(0, n, 1000):
        yield "".join(part.format(i=i) for i in range(start, min(n, start + 1000)))


def demo_without_interval():
    old = "[output]\ninterval_s = 5.0e-6\n"
    if old not in DEMO:
        raise AssertionError(f"the demo no longer holds {old!r}")
    return DEMO.replace(old, "")


def garbage_run_directory(d):
    write(d, "summary.json", garbage(3000, 3))
    write(d, "charge.pvd", garbage(3000, 4))
    return ["report", d]


def random_checkpoint(d):
    ck = write(d, "step_000000000010.ckpt", garbage(200_000, 7))
    return ["run", DEMO_PATH, "--restart", ck, "--out", d / "out", "--quiet"]


def nested(open_, close, depth):
    return "deep = " + open_ * depth + close * depth + "\n"


def with_many_keys(n):
    """The demo with n unknown keys k0 ... k<n-1> in its [time] table, as chunks."""
    head, tail = DEMO.split("safety_factor = 0.9\n")
    yield head + "safety_factor = 0.9\n"
    for start in range(0, n, 10_000):
        yield "".join(f"k{i}=0\n" for i in range(start, min(n, start + 10_000)))
    yield tail


def split_demo(old):
    """The demo before and after `old` (which it must hold once)."""
    if DEMO.count(old) != 1:
        raise AssertionError(f"the demo does not hold {old!r} once")
    return DEMO.split(old)


def symlink_loop(d):
    p = d / "loop.toml"
    os.symlink(p, p)
    return ["check", p]


# ---------------------------------------------------------------------------------------------
# The catalogue: (name, build(d) -> args, expected exit code(s), needles in stderr[, timeout]).
# A needle "{d}" stands for the case's directory.
# ---------------------------------------------------------------------------------------------

E_IN, E_NUM = 2, 3
# The line of a max_steps key added after the demo's safety_factor: a TOML-level error (a number
# TOML cannot hold) names the file, this line and the column, not yet a key.
MAX_STEPS_LINE = DEMO.splitlines().index("safety_factor = 0.9") + 2

CASES = [
    # --- scenario files that are not TOML, or pathological TOML ---
    ("scenario_binary_garbage",
     lambda d: ["check", write(d, "garbage.toml", garbage(65536, 1))],
     E_IN, ["garbage.toml"]),
    ("scenario_empty_file",
     lambda d: ["check", write(d, "empty.toml", b"")],
     E_IN, ["empty.toml", "key 'scenario'"]),
    ("scenario_10mb_single_line",
     lambda d: ["check", write(d, "oneline.toml", repeat("x", 10 << 20))],
     E_IN, ["oneline.toml"]),
    ("scenario_3mb_single_line",     # below the reader's size limit: the parser sees it
     lambda d: ["check", write(d, "oneline3.toml", repeat("x", 3 << 20))],
     E_IN, ["oneline3.toml:1"]),
    ("scenario_10mb_unterminated_string_value",
     lambda d: ["check", write(d, "longname.toml", split_demo('name = "demo"')[0], 'name = "',
                              repeat("n", 10 << 20))],
     E_IN, ["longname.toml"]),
    ("scenario_3mb_string_value",
     lambda d: ["check", write(d, "longdesc.toml", split_demo('description = "')[0],
                              'description = "', repeat("n", 3 << 20), '"\n',
                              split_demo('description = "')[1].split("\n", 1)[1].replace(
                                  "end_time_s = 4.0e-5", "end_time_s = -4.0e-5"))],
     E_IN, ["longdesc.toml:", "scenario.end_time_s"]),
    ("scenario_10000_nested_arrays",
     lambda d: ["check", write(d, "deep_arrays.toml", DEMO + nested("[", "]", 10000))],
     E_IN, ["deep_arrays.toml"]),
    ("scenario_10000_nested_inline_tables",
     lambda d: ["check", write(d, "deep_tables.toml",
                              DEMO + "deep = " + "{a = " * 10000 + "1" + "}" * 10000 + "\n")],
     E_IN, ["deep_tables.toml"]),
    ("scenario_10000_deep_dotted_table_header",
     lambda d: ["check", write(d, "deep_header.toml",
                              DEMO + "[" + ".".join(["t"] * 10000) + "]\nx = 1\n")],
     E_IN, ["deep_header.toml"]),
    ("scenario_million_unknown_keys",
     lambda d: ["check", write(d, "keys.toml", with_many_keys(1_000_000))],
     E_IN, ["keys.toml"]),
    ("scenario_300000_unknown_keys",  # below the reader's size limit: each key is checked
     lambda d: ["check", write(d, "keys300k.toml", with_many_keys(300_000))],
     E_IN, ["keys300k.toml", "time.k0"]),
    ("scenario_non_utf8_bytes",
     lambda d: ["check", write(d, "latin1.toml", DEMO.encode().replace(
         b'name = "demo"', b'name = "d\xe9m\xff\xfeo"'))],
     E_IN, ["latin1.toml"]),
    ("scenario_string_where_table_expected",
     lambda d: ["check", write(d, "region_string.toml",
                              demo_with('region = { type = "disk", center_m = [0.0, 0.0], '
                                        'radius_m = 0.1 }', 'region = "disk"'))],
     E_IN, ["region_string.toml", "parts[0].region"]),
    ("scenario_table_is_array_of_tables",
     lambda d: ["check", write(d, "scenario_array.toml", demo_with("[scenario]", "[[scenario]]"))],
     E_IN, ["scenario_array.toml", "scenario"]),

    # --- non-finite and absurd numbers ---
    ("spacing_nan",
     lambda d: ["check", write(d, "nan.toml", demo_with("spacing_m = 0.005", "spacing_m = nan"))],
     E_IN, ["nan.toml", "parts[0].spacing_m"]),
    ("initial_density_inf",
     lambda d: ["check", write(d, "inf.toml", demo_with(
         "[[parts.detonation]]", "[parts.initial]\ndensity_kg_m3 = inf\n[[parts.detonation]]"))],
     E_IN, ["inf.toml", "parts[0].initial.density_kg_m3"]),
    ("material_density_minus_inf",
     lambda d: ["check", write(d, "minf.toml", demo_with("rho0_kg_m3 = 1630.0",
                                                        "rho0_kg_m3 = -inf"))],
     E_IN, ["minf.toml", "materials[0].rho0_kg_m3"]),
    ("end_time_inf",
     lambda d: ["check", DEMO_PATH, *sets("scenario.end_time_s=inf")],
     E_IN, ["scenario.end_time_s"]),
    ("end_time_minus_inf",
     lambda d: ["check", DEMO_PATH, *sets("scenario.end_time_s=-inf")],
     E_IN, ["scenario.end_time_s"]),
    ("end_time_zero",
     lambda d: run_args(d, DEMO_PATH, *sets("scenario.end_time_s=0")),
     E_IN, ["scenario.end_time_s"]),
    ("end_time_negative",
     lambda d: ["check", DEMO_PATH, *sets("scenario.end_time_s=-4e-5")],
     E_IN, ["scenario.end_time_s"]),
    ("negative_density_set",
     lambda d: ["check", DEMO_PATH, *sets("materials.tnt.rho0_kg_m3=-1630")],
     E_IN, ["materials[0].rho0_kg_m3"]),
    ("zero_spacing_set",
     lambda d: ["check", DEMO_PATH, *sets("parts.charge.spacing_m=0")],
     E_IN, ["parts[0].spacing_m"]),
    ("detonation_time_nan",
     lambda d: ["check", write(d, "det_nan.toml", demo_with("time_s = 0.0", "time_s = nan"))],
     E_IN, ["det_nan.toml", "parts[0].detonation[0].time_s"]),
    ("initial_velocity_inf",
     lambda d: ["check", write(d, "vel_inf.toml", demo_with(
         "[[parts.detonation]]",
         "[parts.initial]\nvelocity_m_s = [inf, 0.0]\n[[parts.detonation]]"))],
     E_IN, ["vel_inf.toml", "parts[0].initial.velocity_m_s"]),
    ("integer_key_1e400",
     lambda d: ["check", write(d, "int_1e400.toml", demo_with(
         "safety_factor = 0.9", "safety_factor = 0.9\nmax_steps = 1e400"))],
     E_IN, [("time.max_steps", f"int_1e400.toml:{MAX_STEPS_LINE}:")]),
    ("integer_key_overflowing_int64",
     lambda d: ["check", write(d, "int_overflow.toml", demo_with(
         "safety_factor = 0.9", "safety_factor = 0.9\nmax_steps = 99999999999999999999999"))],
     E_IN, [("time.max_steps", f"int_overflow.toml:{MAX_STEPS_LINE}:")]),
    ("vector_of_a_million_entries",
     lambda d: ["check", write(d, "long_vector.toml", split_demo("max_m = [1.0, 1.0]")[0],
                              "max_m = [", repeat("1,", 1_000_000), "1]",
                              split_demo("max_m = [1.0, 1.0]")[1])],
     E_IN, ["long_vector.toml", "domain.max_m"]),

    # --- absurd sizes: refused before allocating ---
    ("spacing_1e-9_run",
     lambda d: run_args(d, DEMO_PATH, *sets("parts.charge.spacing_m=1e-9")),
     E_IN, [("parts[0].spacing_m", "parts.charge.spacing_m")]),
    ("spacing_1e-9_check",
     lambda d: ["check", DEMO_PATH, *sets("parts.charge.spacing_m=1e-9")],
     E_IN, [("parts[0].spacing_m", "parts.charge.spacing_m")]),
    ("region_of_1e6_m",
     lambda d: run_args(d, write(d, "huge_region.toml", demo_with(
         "radius_m = 0.1", "radius_m = 1.0e6").replace(
         "min_m = [-1.0, -1.0]", "min_m = [-2.0e6, -2.0e6]").replace(
         "max_m = [1.0, 1.0]", "max_m = [2.0e6, 2.0e6]"))),
     E_IN, ["huge_region.toml", ("parts[0]", "parts.charge", "'charge'")]),
    ("zone_spacing_1e-9",
     lambda d: run_args(d, write(d, "zone.toml", demo_with(
         "[[parts.detonation]]",
         "[[parts.zones]]\nregion = { type = \"box\", min_m = [-0.05, -0.05], "
         "max_m = [0.05, 0.05] }\nspacing_m = 1e-9\n[[parts.detonation]]"))),
     E_IN, ["zone.toml", ("zones[0].spacing_m", "zones.0.spacing_m")]),
    ("fem_structured_spacing_1e-9",
     lambda d: run_args(d, write(d, "fem_tiny.toml", fem_box(spacing=1e-9))),
     E_IN, ["fem_tiny.toml", ("parts[0].spacing_m", "parts.plate.spacing_m")]),
    ("dem_grains_1e-9",
     lambda d: run_args(d, write(d, "dem_tiny.toml", dem_box(1e-9, spacing=2.1e-9))),
     E_IN, ["dem_tiny.toml", ("parts[0].spacing_m", "parts.sand.spacing_m")]),
    ("dem_random_packing_of_1e-7_grains",
     lambda d: run_args(d, write(d, "dem_random.toml", dem_box(
         1e-7, packing={"method": "random", "porosity": 0.4}))),
     E_IN, ["dem_random.toml", ("parts[0]", "parts.sand", "'sand'")]),
    ("output_interval_1e-15",
     lambda d: run_args(d, DEMO_PATH, *sets("output.interval_s=1e-15")),
     E_IN, ["output.interval_s"]),
    ("end_time_1e30_with_fixed_dt",
     lambda d: run_args(d, DEMO_PATH, *sets("scenario.end_time_s=1e30", "time.fixed_dt_s=1e-8")),
     E_IN, [("scenario.end_time_s", "time.fixed_dt_s")]),

    ("end_time_1e30_with_fixed_dt_default_interval",  # 20 frames, 1e38 steps
     lambda d: run_args(d, write(d, "forever.toml", demo_without_interval()),
                        *sets("scenario.end_time_s=1e30", "time.fixed_dt_s=1e-8",
                              'domain.outflow="remove"')),
     E_IN, [("scenario.end_time_s", "time.fixed_dt_s")], HANG_TIMEOUT),
    ("20000_parts_all_overlapping",  # 2e8 overlapping pairs: each an error, unless bounded
     lambda d: ["check", write(d, "crowd.toml", many_overlapping_parts(20_000))],
     E_IN, ["crowd.toml", "'p0'"]),

    # --- inconsistent scenarios ---
    ("contact_with_unknown_part",
     lambda d: ["check", write(d, "contact.toml",
                              DEMO + '\n[[contacts]]\nparts = ["charge", "nope"]\n')],
     E_IN, ["contact.toml", "contacts[0].parts[1]", "nope"]),
    ("contact_of_a_part_with_itself",
     lambda d: ["check", write(d, "contact_self.toml",
                              DEMO + '\n[[contacts]]\nparts = ["charge", "charge"]\n')],
     E_IN, ["contact_self.toml", "contacts[0].parts"]),
    ("probe_plate_is_not_fem",
     lambda d: ["check", write(d, "probe.toml", DEMO + '\n[probes]\nplate = "charge"\n')],
     E_IN, ["probe.toml", "probes.plate"]),
    ("carve_of_unknown_part",
     lambda d: ["check", write(d, "carve.toml", demo_with("radius_m = 0.1 }",
                                                        'radius_m = 0.1 }\ncarve = ["ghost"]'))],
     E_IN, ["carve.toml", "parts[0].carve[0]", "ghost"]),
    ("domain_min_above_max",
     lambda d: ["check", DEMO_PATH, *sets("domain.min_m=[2.0, 2.0]")],
     E_IN, [("domain.min_m", "domain.max_m")]),
    ("unknown_method",
     lambda d: ["check", write(d, "mpm.toml", demo_with('method = "sph"', 'method = "mpm"'))],
     E_IN, ["mpm.toml", "parts[0].method"]),
    ("unknown_material_reference",
     lambda d: ["check", write(d, "rdx.toml", demo_with('material = "tnt"', 'material = "rdx"'))],
     E_IN, ["rdx.toml", "parts[0].material", "rdx"]),
    ("duplicate_part_names",
     lambda d: ["check", write(d, "dup_parts.toml",
                              DEMO + second_part("charge", x=0.5))],
     E_IN, ["dup_parts.toml", "parts[1].name"]),
    ("duplicate_material_names",
     lambda d: ["check", write(d, "dup_mats.toml", DEMO + SECOND_MATERIAL)],
     E_IN, ["dup_mats.toml", "materials[1].name"]),
    ("part_outside_domain",
     lambda d: ["check", write(d, "outside.toml", demo_with("center_m = [0.0, 0.0]",
                                                          "center_m = [5.0, 5.0]"))],
     E_IN, ["outside.toml", "parts[0].region"]),
    ("overlapping_parts",
     lambda d: ["check", write(d, "overlap.toml",
                              DEMO + second_part("booster", x=0.05))],
     E_IN, ["overlap.toml", "booster"]),
    ("detonation_point_outside_charge",
     lambda d: ["check", write(d, "det_out.toml", demo_with("point_m = [0.0, 0.0]",
                                                          "point_m = [0.5, 0.5]"))],
     E_IN, ["det_out.toml", "parts[0].detonation[0].point_m"]),
    ("fixed_dt_above_stable_step",
     lambda d: run_args(d, DEMO_PATH, *sets("time.fixed_dt_s=1e-3")),
     E_IN, ["time.fixed_dt_s", "part 'charge'"]),
    ("jwl_a_1e300",
     lambda d: run_args(d, write(d, "jwl_huge.toml", demo_with("a_pa = 373.8e9", "a_pa = 1e300")),
                        *sets("scenario.end_time_s=2e-6")),
     (E_IN, E_NUM), [("materials[0].a_pa", "'charge'")]),
    ("level_whose_override_is_bad",
     lambda d: ["check", write(d, "levels.toml", DEMO + '\n[levels.broken]\ndescription = "x"\n'
                               'set = ["parts.nosuchpart.spacing_m = 0.01"]\n'),
                "--level", "broken"],
     E_IN, ["parts.nosuchpart.spacing_m"]),

    # --- numerical failure: exit 3, the part named ---
    ("blow_up_cfl_1_safety_1",
     lambda d: run_args(d, "demo", *sets("parts.charge.sph.cfl=1", "time.safety_factor=1")),
     E_NUM, ["part 'charge'"]),

    # --- command lines ---
    ("set_unknown_key",
     lambda d: ["check", DEMO_PATH, *sets("time.bogus_key=1")],
     E_IN, ["time.bogus_key"]),
    ("set_wrong_type_string_for_integer",
     lambda d: ["check", DEMO_PATH, *sets('scenario.dimension="three"')],
     E_IN, ["scenario.dimension"]),
    ("set_number_where_table_expected",
     lambda d: ["check", DEMO_PATH, *sets("parts.charge.region=5")],
     E_IN, ["parts[0].region"]),
    ("set_without_equals",
     lambda d: run_args(d, DEMO_PATH, "--set", "time.safety_factor"),
     E_IN, ["time.safety_factor"]),
    ("set_unparsable_value",
     lambda d: ["check", DEMO_PATH, *sets("time.safety_factor=[[[")],
     E_IN, ["time.safety_factor"]),
    ("set_index_out_of_range",
     lambda d: ["check", DEMO_PATH, *sets("parts.99.spacing_m=0.01")],
     E_IN, ["parts.99"]),
    ("level_that_does_not_exist",
     lambda d: ["check", "paper-20cm", "--level", "ultrafine"],
     E_IN, ["ultrafine"]),
    ("level_on_scenario_without_levels",
     lambda d: run_args(d, DEMO_PATH, "--level", "fine"),
     E_IN, ["--level fine"]),
    ("threads_0",
     lambda d: run_args(d, DEMO_PATH, "--threads", "0"),
     E_IN, ["--threads"]),
    ("threads_minus_1",
     lambda d: run_args(d, DEMO_PATH, "--threads", "-1"),
     E_IN, ["--threads"]),
    ("threads_100000",
     lambda d: run_args(d, DEMO_PATH, "--threads", "100000"),
     E_IN, ["--threads"]),
    ("threads_not_a_number",
     lambda d: run_args(d, DEMO_PATH, "--threads", "many"),
     E_IN, ["--threads"]),
    ("set_empty_key",
     lambda d: ["check", DEMO_PATH, "--set", "=1"],
     E_IN, ["--set =1"]),
    ("set_fixed_dt_nan",
     lambda d: ["check", DEMO_PATH, *sets("time.fixed_dt_s=nan")],
     E_IN, ["time.fixed_dt_s"]),
    ("out_below_a_regular_file",
     lambda d: ["run", DEMO_PATH, "--out", "/dev/null/run", "--quiet"],
     E_IN, ["--out", "/dev/null/run"]),
    ("out_is_a_regular_file",
     lambda d: ["run", DEMO_PATH, "--out", write(d, "not_a_dir", "x"), "--quiet"],
     E_IN, ["not_a_dir"]),

    # --- scenario paths that are not regular files ---
    ("scenario_is_a_directory",
     lambda d: ["check", d],
     E_IN, ["{d}"]),
    ("scenario_is_dev_zero",
     lambda d: run_args(d, "/dev/zero"),
     E_IN, ["/dev/zero"]),
    ("scenario_is_a_fifo",
     lambda d: ["check", make_fifo(d, "scenario.fifo")],
     E_IN, ["scenario.fifo"]),
    ("scenario_missing_file",
     lambda d: run_args(d, d / "no_such_scenario.toml"),
     E_IN, ["no_such_scenario.toml"]),
    ("scenario_symlink_loop",
     symlink_loop,
     E_IN, ["loop.toml"]),

    # --- meshes ---
    ("mesh_binary_garbage",
     mesh_case(garbage(50_000, 2), "garbage.msh"),
     E_IN, ["garbage.msh"]),
    ("mesh_empty",
     mesh_case(b"", "empty.msh"),
     E_IN, ["empty.msh"]),
    ("mesh_truncated",
     mesh_case(PLATE_MSH[: PLATE_MSH.index("$Elements") + 20], "truncated.msh"),
     E_IN, ["truncated.msh"]),
    ("mesh_element_references_missing_node",
     mesh_case(mesh_edit(element_with_missing_node), "dangling.msh"),
     E_IN, ["dangling.msh", "77777"]),
    ("mesh_element_count_1e12",
     mesh_case(mesh_edit(after_header("$Elements", "2 1000000000000 1 1000000000000")),
               "elements_1e12.msh", command="run"),
     E_IN, ["elements_1e12.msh"]),
    ("mesh_element_block_of_1e12",
     mesh_case(mesh_edit(replace_line("2 1 3 2", "2 1 3 1000000000000")), "block_1e12.msh",
               command="run"),
     E_IN, ["block_1e12.msh"]),
    ("mesh_node_count_1e12",
     mesh_case(mesh_edit(after_header("$Nodes", "3 1000000000000 1 1000000000000")),
               "nodes_1e12.msh", command="run"),
     E_IN, ["nodes_1e12.msh"]),
    ("mesh_entity_count_1e12",
     mesh_case(mesh_edit(after_header("$Entities", "1000000000000 4 1 0")), "entities_1e12.msh"),
     E_IN, ["entities_1e12.msh"]),
    ("mesh_node_coordinate_nan",
     mesh_case(mesh_edit(replace_line("2 1 0", "nan 1 0")), "nan.msh"),
     E_IN, ["nan.msh"]),
    ("mesh_format_2_2",
     mesh_case(mesh_edit(replace_line("4.1 0 8", "2.2 0 8")), "old.msh"),
     E_IN, ["old.msh"]),
    ("mesh_group_that_does_not_exist",
     lambda d: ["check", write(d, "group.toml", mesh_scenario(
         write(d, "plate.msh", PLATE_MSH), mesh_group="no_such_group"))],
     E_IN, ["parts[0].fem.mesh_group", "no_such_group"]),
    ("mesh_path_is_a_directory",
     lambda d: ["check", write(d, "mesh.toml", mesh_scenario(d))],
     E_IN, ["parts[0].fem.mesh_file"]),
    ("mesh_path_is_dev_zero",
     lambda d: ["check", write(d, "mesh.toml", mesh_scenario("/dev/zero"))],
     E_IN, ["parts[0].fem.mesh_file", "/dev/zero"]),
    ("mesh_path_is_a_fifo",
     lambda d: ["check", write(d, "mesh.toml", mesh_scenario(make_fifo(d, "mesh.fifo")))],
     E_IN, ["parts[0].fem.mesh_file", "mesh.fifo"]),

    # --- run directories and checkpoints ---
    ("resume_directory_without_checkpoint",
     lambda d: ["run", "--resume", d, "--quiet"],
     E_IN, ["{d}", "checkpoint"]),
    ("resume_directory_that_does_not_exist",
     lambda d: ["run", DEMO_PATH, "--resume", d / "no_such_run", "--quiet"],
     E_IN, ["no_such_run"]),
    ("restart_random_bytes",
     random_checkpoint,
     E_IN, ["step_000000000010.ckpt"]),
    ("restart_truncated_checkpoint",
     truncated_checkpoint,
     E_IN, [".ckpt", "truncated"]),
    ("restart_checkpoint_with_huge_string_length",
     forged_checkpoint(huge_string_length),
     E_IN, ["forged.ckpt"]),
    ("restart_checkpoint_with_1e18_parts",
     forged_checkpoint(huge_part_count),
     E_IN, ["forged.ckpt"]),
    ("restart_sparse_2gib_checkpoint",
     sparse_checkpoint,
     E_IN, ["step_000000000006.ckpt"], HANG_TIMEOUT),
    ("restart_from_dev_zero",
     lambda d: ["run", DEMO_PATH, "--restart", "/dev/zero", "--out", d / "out", "--quiet"],
     E_IN, ["/dev/zero"], HANG_TIMEOUT),
    ("restart_from_a_fifo",
     lambda d: ["run", DEMO_PATH, "--restart", make_fifo(d, "step_000000000001.ckpt"),
                "--out", d / "out", "--quiet"],
     E_IN, ["step_000000000001.ckpt"], HANG_TIMEOUT),
    ("resume_with_a_fifo_as_checkpoint",
     resume_with_fifo_checkpoint,
     E_IN, ["step_000000000009.ckpt"], HANG_TIMEOUT),
    ("resume_with_garbage_command_file",
     resume_with_command(lambda text: "\x00\x01 = = [[[ \n" + text),
     E_IN, ["crater-command.toml"]),
    ("resume_with_100000_threads_in_command_file",
     resume_with_command(command_threads(100000)),
     E_IN, ["crater-command.toml", "threads"]),
    ("resume_with_string_threads_in_command_file",
     resume_with_command(command_threads('"many"')),
     E_IN, ["crater-command.toml", "threads"]),
    ("restart_from_a_directory",
     lambda d: ["run", DEMO_PATH, "--restart", d, "--out", d / "out", "--quiet"],
     E_IN, ["{d}"]),
    ("report_of_an_empty_directory",
     lambda d: ["report", d],
     E_IN, ["{d}"]),
    ("report_of_garbage_summary_and_pvd",
     garbage_run_directory,
     E_IN, ["summary.json"]),
    ("report_times_not_numbers",
     lambda d: ["report", make_checkpoint(d).parent.parent, "--times", "abc,-1",
                "--out", d / "report"],
     E_IN, ["--times", "abc"]),
    ("report_of_a_regular_file",
     lambda d: ["report", write(d, "summary.json", "{not json")],
     E_IN, ["summary.json"]),
]


# ---------------------------------------------------------------------------------------------
# Running one case.
# ---------------------------------------------------------------------------------------------

def rss_now(pid):
    """Resident set size of a running process [bytes], or 0."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def kill_group(pid):
    """Kills the child this test started and whatever it started (its own session)."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


class Outcome:
    def __init__(self):
        self.code = None        # exit code (negative: killed by that signal)
        self.peak = 0           # peak RSS [bytes]
        self.seconds = 0.0
        self.hung = False
        self.killed_for_memory = False
        self.stderr = ""
        self.command = ""


def run_child(args, timeout, cwd):
    """Runs crater with args in its own session; returns an Outcome with that child's peak RSS:
    the ru_maxrss os.wait4 returns for it (which starts from this process's own high-water mark,
    inherited at fork, so this test writes its big inputs in chunks), and VmRSS sampled every
    10 ms. A child past the timeout or past KILL_RSS is killed (with what it started)."""
    o = Outcome()
    argv = [BIN, *map(str, args)]
    o.command = " ".join(argv)
    err_path = cwd / "stderr.txt"
    t0 = time.monotonic()
    status = usage = None
    with open(err_path, "wb") as err:
        proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=err, cwd=cwd, start_new_session=True)
        try:
            while True:
                pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
                if pid != 0:
                    break
                o.peak = max(o.peak, rss_now(proc.pid))
                if o.peak > KILL_RSS and not o.killed_for_memory:
                    o.killed_for_memory = True
                    kill_group(proc.pid)
                elif time.monotonic() - t0 > timeout and not o.hung:
                    o.hung = True
                    kill_group(proc.pid)
                time.sleep(0.01)
        finally:
            if usage is None or pid == 0:   # interrupted: do not leave the child behind
                kill_group(proc.pid)
                _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)  # reaped: Popen must not wait
    o.seconds = time.monotonic() - t0
    o.code = proc.returncode
    o.peak = max(o.peak, usage.ru_maxrss * 1024)  # Linux: KiB
    with open(err_path, "rb") as f:
        raw = f.read(1 << 20)   # the first MiB is plenty to judge the message
    o.stderr = raw.decode("utf-8", errors="replace")
    return o


def expand(needle, d):
    return needle.replace("{d}", str(d))


class HostileCatalogue(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        TMP.mkdir(parents=True, exist_ok=True)
        cls.root = Path(tempfile.mkdtemp(prefix="hostile_", dir=TMP))
        cls.table = []

    @classmethod
    def tearDownClass(cls):
        verbose = os.environ.get("CRATER_HOSTILE_VERBOSE")
        print(f"\n{'case':<44} {'exit':>5} {'peak MB':>8} {'s':>6}  result "
              f"(peak: ru_maxrss of the child, at least this test's own "
              f"{cls.own_peak() / 1e6:.0f} MB)", file=sys.stderr)
        for name, o, ok in cls.table:
            print(f"{name:<44} {str(o.code):>5} {o.peak / 1e6:>8.1f} {o.seconds:>6.2f}  "
                  f"{'ok' if ok else 'FAIL'}", file=sys.stderr)
            if verbose:
                for line in o.stderr.splitlines()[:3]:
                    print(f"    | {line[:300]}", file=sys.stderr)
        if not verbose:
            shutil.rmtree(cls.root, ignore_errors=True)

    @staticmethod
    def own_peak():
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024

    def test_catalogue_size(self):
        names = [c[0] for c in CASES]
        self.assertEqual(len(names), len(set(names)), "case names must be unique")
        self.assertGreaterEqual(len(CASES), 35)

    def test_catalogue(self):
        for k, case in enumerate(CASES):
            name, build, expected, needles = case[:4]
            timeout = case[4] if len(case) > 4 else DEFAULT_TIMEOUT
            with self.subTest(case=name):
                d = self.root / f"case{k:03d}"  # not the name: a needle must not match the path
                d.mkdir()
                args = build(d)
                o = run_child(args, timeout, d)
                ok = False
                try:
                    self.check_outcome(name, o, expected, [expand_any(n, d) for n in needles])
                    ok = True
                finally:
                    self.table.append((name, o, ok))

    def check_outcome(self, name, o, expected, needles):
        expected = expected if isinstance(expected, tuple) else (expected,)
        shown = (f"\ncommand: {o.command}\nexit {o.code}, peak RSS {o.peak / 1e6:.1f} MB, "
                 f"{o.seconds:.2f} s\nstderr:\n{o.stderr[:4000]}")
        self.assertFalse(o.hung, f"{name}: no answer within the timeout (killed){shown}")
        self.assertFalse(o.killed_for_memory,
                         f"{name}: killed past {KILL_RSS / GIB:.2f} GiB of memory{shown}")
        self.assertGreaterEqual(o.code, 0, f"{name}: killed by signal {-o.code}{shown}")
        self.assertIn(o.code, expected, f"{name}: exit {o.code}, expected {expected}{shown}")
        for marker in CRASH_MARKERS:
            self.assertNotIn(marker, o.stderr, f"{name}: crash marker {marker!r}{shown}")
        for n in needles:
            alternatives = n if isinstance(n, tuple) else (n,)
            self.assertTrue(any(a in o.stderr for a in alternatives),
                            f"{name}: stderr names none of {alternatives}{shown}")
        self.assertLess(o.peak, MEMORY_LIMIT,
                        f"{name}: peak RSS {o.peak / 1e6:.0f} MB before refusing{shown}")


def expand_any(needle, d):
    if isinstance(needle, tuple):
        return tuple(expand(n, d) for n in needle)
    return expand(needle, d)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
