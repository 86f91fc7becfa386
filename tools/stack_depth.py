#!/usr/bin/env python3
"""Worst-case stack depth of the firmware core by call graph (Cortex-M builds).

    python3 tools/stack_depth.py build-m7 [--elf build-m7/demo.elf] [--json runs/bench/stack-build-m7.json]

The core is compiled with -fcallgraph-info=su (GCC >= 10; CMakeLists.txt,
Generic builds): every object gets a .ci file (VCG graph) naming each
function with its frame ("N bytes (static)") and each call it makes. This
script joins the .ci files of the core, then adds the functions the core
calls outside itself (libgcc's soft-double helpers __aeabi_d*, newlib's
sqrt, fmod, floor, memcpy, memset): their frames are read from the linked
image's disassembly (arm-none-eabi-objdump), counting every instruction that
moves sp down in the function (push, vpush, stmdb sp!, str/strd with
[sp, #-N]!, sub sp) and following bl/b into other functions and
fall-through into the next symbol. Both parts are upper bounds for their
function (every push counted, whatever branch it is on).

Reported: for every C-ABI entry point (pyins_*), the deepest path and its
total in bytes, and the largest single frame. A recursive cycle or a frame
GCC marks dynamic makes the bound unknown (reported, exit status 1).
Not included: what the caller of the entry point uses, and an exception
frame if the entry point runs in an interrupt handler (32 bytes, 104 with
the FPU context).
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
from functools import lru_cache

NODE = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"(.*)\}')
EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
FRAME = re.compile(r"(\d+) bytes \(([a-z,]+)\)")
#: What an external function not found in the image is assumed to use [bytes]
#: (more than any libgcc/newlib leaf seen in these images).
UNKNOWN_EXTERNAL_BYTES = 64


def _key(title):
    """One name per function: GCC prefixes some titles (templates, internal
    linkage) with their source file in the defining object only."""
    m = re.match(r"^.*\.(?:c|cc|cpp|cxx):(.+)$", title)
    return m.group(1) if m else title


def _pretty(label, title):
    """A short readable name: no return type, template arguments or
    parameters; GCC labels clones (.part.0) by their suffix only."""
    name = label
    if not re.match(r"^[A-Za-z_~]", name):
        name = title
    depth, out = 0, []
    for ch in name:
        if ch == "<":
            depth += 1
        elif ch == ">":
            depth -= 1
        elif depth == 0:
            out.append(ch)
    name = "".join(out).split("(")[0].strip()
    return name.split(" ")[-1] if " " in name else name


def read_callgraph(build):
    """frames: {function: (bytes, kind, pretty name)}; calls: {function: set(callees)}."""
    frames, calls, names = {}, {}, {}
    pattern = os.path.join(build, "CMakeFiles", "pyins_core_obj.dir", "**", "*.ci")
    files = sorted(glob.glob(pattern, recursive=True))
    if not files:
        raise FileNotFoundError(f"no .ci files under {build} (configure with the arm-none-eabi toolchain "
                                f"file: CMakeLists.txt adds -fcallgraph-info=su)")
    for path in files:
        with open(path) as f:
            for line in f:
                m = NODE.search(line)
                if m:
                    title, label = _key(m.group(1)), m.group(2)
                    names.setdefault(title, _pretty(label.split("\\n")[0], title))
                    fm = FRAME.search(label)
                    if fm:
                        frames[title] = (int(fm.group(1)), fm.group(2), _pretty(label.split("\\n")[0], title))
                    continue
                m = EDGE.search(line)
                if m:
                    calls.setdefault(_key(m.group(1)), set()).add(_key(m.group(2)))
    return frames, calls, names


class Image:
    """Stack use of the functions of a linked image, from its disassembly."""

    TERMINAL = re.compile(r"^(pop(\.w)?\s+\{[^}]*\bpc\}|bx\s+lr|ldr(\.w)?\s+pc,|ldmia(\.w)?\s+sp!,\s*\{[^}]*\bpc\}"
                          r"|b(\.n|\.w)?\s+[0-9a-f]+ <)")

    def __init__(self, elf, objdump="arm-none-eabi-objdump", nm="arm-none-eabi-nm"):
        dis = subprocess.run([objdump, "-d", "--no-show-raw-insn", elf], capture_output=True, text=True,
                             check=True).stdout
        syms = subprocess.run([nm, elf], capture_output=True, text=True, check=True).stdout
        self.addr_of = {}
        for line in syms.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[1] in "TtWw":
                self.addr_of[parts[2]] = int(parts[0], 16)
        self.blocks = {}        # address -> [(mnemonic line)]
        self.block_name = {}    # address -> label
        self.order = []         # block addresses in order
        cur = None
        for line in dis.splitlines():
            m = re.match(r"^([0-9a-f]+) <([^>]+)>:$", line)
            if m:
                cur = int(m.group(1), 16)
                self.blocks[cur] = []
                self.block_name[cur] = m.group(2)
                self.order.append(cur)
                continue
            m = re.match(r"^\s+[0-9a-f]+:\s+(.*)$", line)
            if m and cur is not None:
                self.blocks[cur].append(m.group(1).split("@")[0].strip())
        self.next_block = {a: b for a, b in zip(self.order, self.order[1:])}
        self.name_addr = {v: k for k, v in self.block_name.items()}

    @staticmethod
    def _regs(reglist):
        n = 0
        for part in reglist.split(","):
            part = part.strip()
            m = re.match(r"([rsd])(\d+)-[rsd](\d+)$", part)
            if m:
                n += int(m.group(3)) - int(m.group(2)) + 1
            elif part:
                n += 1
        return n

    def own_bytes(self, addr):
        """Every sp decrement in the block (an upper bound of its frame)."""
        total, dynamic = 0, False
        for ins in self.blocks.get(addr, []):
            m = re.match(r"^(push|stmdb|stmfd)(\.w)?\s+(sp!,\s*)?\{([^}]*)\}", ins)
            if m and (m.group(1) == "push" or m.group(3)):
                total += 4 * self._regs(m.group(4))
                continue
            m = re.match(r"^(vpush|vstmdb)(\.\d+)?\s+(sp!,\s*)?\{([^}]*)\}", ins)
            if m and (m.group(1) == "vpush" or m.group(3)):
                regs = m.group(4)
                total += (8 if "d" in regs else 4) * self._regs(regs)
                continue
            m = re.search(r"\[sp, #-(\d+)\]!", ins)
            if m and re.match(r"^str", ins):
                total += int(m.group(1))
                continue
            m = re.match(r"^sub(s|w)?(\.w)?\s+sp,\s*(sp,\s*)?#(\d+)", ins)
            if m:
                total += int(m.group(4))
                continue
            if re.match(r"^sub(s|w)?(\.w)?\s+sp,\s*(sp,\s*)?[a-z]", ins):
                dynamic = True
        return total, dynamic

    def successors(self, addr):
        """Other blocks this one calls, branches into or falls through to."""
        out = set()
        ins_list = self.blocks.get(addr, [])
        for ins in ins_list:
            m = re.match(r"^(bl|blx|b|b\.n|b\.w|b[a-z]{2}(\.n|\.w)?|cbn?z)\s+.*?([0-9a-f]+) <([^>+]+)(\+0x[0-9a-f]+)?>",
                         ins)
            if m and m.group(4) != self.block_name[addr]:
                target = int(m.group(3), 16)
                # the block containing the target
                owner = max((a for a in self.order if a <= target), default=None)
                if owner is not None and owner != addr:
                    out.add(owner)
        # fall-through into the next symbol: decided by the last real
        # instruction (not literal-pool words or alignment nops)
        # (0x0000 padding after a function decodes as "movs r0, r0")
        real = [i for i in ins_list if not re.match(r"^(\.word|\.short|\.byte|nop|\.inst|movs\s+r0,\s*r0$)", i)]
        if real and not self.TERMINAL.match(real[-1]) and addr in self.next_block:
            out.add(self.next_block[addr])
        return out

    def worst(self, symbol):
        """(bytes, path, dynamic) of the deepest stack below symbol, or None if absent."""
        if symbol not in self.addr_of:
            return None
        addr = self.addr_of[symbol]
        owner = max((a for a in self.order if a <= addr), default=None)
        if owner is None:
            return None

        @lru_cache(maxsize=None)
        def rec(a, depth=0):
            own, dyn = self.own_bytes(a)
            if depth > 50:
                return own, [self.block_name[a]], True
            best, best_path, best_dyn = 0, [], False
            for s in self.successors(a):
                if s == a:
                    continue
                b, p, d = rec(s, depth + 1)
                if b > best:
                    best, best_path, best_dyn = b, p, d
                dyn = dyn or d
            return own + best, [self.block_name[a]] + best_path, dyn or best_dyn

        return rec(owner)


def analyse(build, elf=None):
    frames, calls, names = read_callgraph(build)
    image = Image(elf) if elf and os.path.exists(elf) else None
    externals = {}
    assumed = []

    def external(fn):
        if fn not in externals:
            got = image.worst(fn) if image else None
            if got is None:
                externals[fn] = (UNKNOWN_EXTERNAL_BYTES, [fn + " (assumed)"], False)
                assumed.append(fn)
            else:
                externals[fn] = got
        return externals[fn]

    memo, on_path, problems = {}, set(), []

    def deepest(fn):
        if fn in memo:
            return memo[fn]
        if fn not in frames:
            b, path, dyn = external(fn)
            if dyn:
                problems.append(f"{fn}: dynamic stack in the image")
            return b, [(fn, b)]
        if fn in on_path:
            problems.append(f"recursion through {names.get(fn, fn)}")
            return 0, []
        on_path.add(fn)
        own, kind, _ = frames[fn]
        if kind != "static":
            problems.append(f"{names.get(fn, fn)}: {kind} frame")
        best, best_path = 0, []
        for callee in sorted(calls.get(fn, ())):
            b, p = deepest(callee)
            if b > best:
                best, best_path = b, p
        on_path.discard(fn)
        memo[fn] = (own + best, [(fn, own)] + best_path)
        return memo[fn]

    entries = sorted(f for f in frames if f.startswith("pyins_"))
    result = {"entries": {}, "assumed_externals": assumed, "problems": problems}
    for e in entries:
        total, path = deepest(e)
        result["entries"][e] = {"bytes": total,
                                "path": [(names.get(f, f), b) for f, b in path]}
    big = max(frames.items(), key=lambda kv: kv[1][0])
    result["max_frame"] = {"bytes": big[1][0], "function": big[1][2]}
    worst = max(result["entries"].items(), key=lambda kv: kv[1]["bytes"])
    result["worst"] = {"entry": worst[0], **worst[1]}
    result["externals"] = {k: v[0] for k, v in sorted(externals.items())}
    return result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build", help="a Cortex-M build directory (build-m7, build-m4)")
    ap.add_argument("--elf", help="linked image for the external functions (default BUILD/demo.elf)")
    ap.add_argument("--json", help="write the figures here (default runs/bench/stack-<build dir name>.json)")
    args = ap.parse_args(argv)
    res = analyse(args.build, args.elf or os.path.join(args.build, "demo.elf"))
    for e, r in sorted(res["entries"].items(), key=lambda kv: -kv[1]["bytes"]):
        print(f"{e:24s} {r['bytes']:6d} bytes  " + " -> ".join(f"{f} {b}" for f, b in r["path"]))
    print(f"largest single frame: {res['max_frame']['bytes']} bytes ({res['max_frame']['function']})")
    if res["assumed_externals"]:
        print(f"not in the image, assumed {UNKNOWN_EXTERNAL_BYTES} bytes: {', '.join(res['assumed_externals'])}")
    for p in res["problems"]:
        print("PROBLEM:", p)
    args.json = args.json or os.path.join("runs", "bench", f"stack-{os.path.basename(os.path.normpath(args.build))}.json")
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        fig = {"worst_stack_bytes": res["worst"]["bytes"], "worst_stack_entry": res["worst"]["entry"],
               "max_frame_bytes": res["max_frame"]["bytes"], "max_frame_function": res["max_frame"]["function"],
               "entry_stack_bytes": {e: r["bytes"] for e, r in res["entries"].items()},
               "external_stack_bytes": res["externals"], "problems": res["problems"]}
        with open(args.json, "w") as f:
            json.dump(fig, f, indent=2)
        print(f"figures: {args.json}")
    return 1 if res["problems"] else 0


if __name__ == "__main__":
    sys.exit(main())
