#!/usr/bin/env python3
"""Compares the onboard example's output files across targets (standard library only: struct, array).

    scripts/onboard-compare.py [--rel-tol R] [--abs-tol A] [--exact NAME ...] REF=FILE NAME=FILE ...

The first file is the reference; every other one is compared with it value by value. The files are
what examples/onboard/onboard_example.c writes: a 16-byte header (magic "FFSRONB1", uint32 doubles per
record, uint32 records), then the records of little-endian IEEE-754 doubles.

Reported per file: whether it is bit-identical; else the number of differing values, the first
(record, index) that differs, the largest difference in units in the last place (ulps), the largest
absolute and relative differences and where they are, and how many values differ at each index of the
record.

A file passes when every value is bit-identical, or, unless it is named with --exact, when every pair
satisfies |a - b| <= max(rel_tol * max(|a|, |b|), abs_tol) (math.isclose). Exit status 0 if all pass,
1 if any differs beyond that, 2 for unreadable or mismatched files. The default tolerances are 0: only
bit-identity passes.
"""
import argparse
import array
import math
import struct
import sys

MAGIC = b"FFSRONB1"
HEADER = struct.Struct("<8sII")


class OutputFile:
    def __init__(self, name, path):
        self.name = name
        self.path = path
        with open(path, "rb") as handle:
            data = handle.read()
        if len(data) < HEADER.size:
            raise ValueError(f"{path}: {len(data)} bytes, shorter than the header")
        magic, self.doubles, self.records = HEADER.unpack_from(data)
        if magic != MAGIC:
            raise ValueError(f"{path}: not an onboard output file (magic {magic!r})")
        expected = HEADER.size + 8 * self.doubles * self.records
        if len(data) != expected:
            raise ValueError(f"{path}: {len(data)} bytes, the header announces {expected} "
                             f"({self.records} records of {self.doubles} doubles): a run cut short?")
        self.values = array.array("d")
        self.values.frombytes(data[HEADER.size:])
        if sys.byteorder != "little":
            self.values.byteswap()
        # The same payload as 64-bit integers, for bit comparison and ulp distances.
        self.bits = array.array("q")
        self.bits.frombytes(data[HEADER.size:])
        if sys.byteorder != "little":
            self.bits.byteswap()


def ordered(bits):
    """Maps a double's bit pattern to an integer that increases with the value (for ulp distances)."""
    return bits if bits >= 0 else -(bits & 0x7FFFFFFFFFFFFFFF)


def record_scales(reference, skip):
    """The largest |value| of each record of the reference, its first `skip` values (labels) left out."""
    n = reference.doubles
    return [max((abs(v) for v in reference.values[r * n + skip:(r + 1) * n]), default=0.0)
            for r in range(reference.records)]


def compare(reference, other, rel_tol, abs_tol, record_rel=0.0, skip=0):
    """Returns a dict of statistics of `other` against `reference`."""
    scales = record_scales(reference, skip) if record_rel > 0 else None
    stats = {"max_record_rel": 0.0, "max_record_rel_at": None, "differing": 0, "first": None, "max_ulps": 0, "max_ulps_at": None, "max_abs": 0.0,
             "max_abs_at": None, "max_rel": 0.0, "max_rel_at": None, "beyond_tolerance": 0, "nan_mismatch": 0,
             "by_index": [0] * reference.doubles}
    n = reference.doubles
    for i, (a_bits, b_bits) in enumerate(zip(reference.bits, other.bits)):
        if a_bits == b_bits:
            continue
        at = (i // n, i % n)
        stats["differing"] += 1
        stats["by_index"][at[1]] += 1
        if stats["first"] is None:
            stats["first"] = at
        a, b = reference.values[i], other.values[i]
        if math.isnan(a) or math.isnan(b):
            stats["nan_mismatch"] += 1
            stats["beyond_tolerance"] += 1
            continue
        ulps = abs(ordered(a_bits) - ordered(b_bits))
        difference = abs(a - b)
        scale = max(abs(a), abs(b))
        relative = difference / scale if scale > 0 else 0.0
        if ulps > stats["max_ulps"]:
            stats["max_ulps"], stats["max_ulps_at"] = ulps, at
        if difference > stats["max_abs"]:
            stats["max_abs"], stats["max_abs_at"] = difference, at
        if relative > stats["max_rel"]:
            stats["max_rel"], stats["max_rel_at"] = relative, at
        record_bound = 0.0
        if scales is not None and scales[at[0]] > 0:
            record_relative = difference / scales[at[0]]
            record_bound = record_rel * scales[at[0]]
            if record_relative > stats["max_record_rel"]:
                stats["max_record_rel"], stats["max_record_rel_at"] = record_relative, at
        if not math.isclose(a, b, rel_tol=rel_tol, abs_tol=max(abs_tol, record_bound)):
            stats["beyond_tolerance"] += 1
    return stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="+", metavar="NAME=FILE", help="the reference first")
    parser.add_argument("--rel-tol", type=float, default=0.0, help="relative tolerance (default 0)")
    parser.add_argument("--abs-tol", type=float, default=0.0, help="absolute tolerance (default 0)")
    parser.add_argument("--record-rel", type=float, default=0.0,
                        help="a value also passes within this fraction of the largest |value| of its record "
                             "in the reference (a command vector's own scale; default 0: off)")
    parser.add_argument("--skip", type=int, default=0,
                        help="leading values of a record that label it (left out of its scale)")
    parser.add_argument("--exact", action="append", default=[], metavar="NAME",
                        help="this file must be bit-identical to the reference, whatever the tolerances")
    args = parser.parse_args()
    if len(args.files) < 2:
        parser.error("give a reference and at least one file to compare with it")

    outputs = []
    try:
        for item in args.files:
            name, separator, path = item.partition("=")
            if not separator:
                name, path = item, item
            outputs.append(OutputFile(name, path))
    except (OSError, ValueError) as error:
        print(f"onboard-compare: {error}", file=sys.stderr)
        return 2
    reference = outputs[0]
    status = 0
    for other in outputs[1:]:
        if (other.doubles, other.records) != (reference.doubles, reference.records):
            print(f"onboard-compare: {other.name}: {other.records} records of {other.doubles} doubles, "
                  f"{reference.name}: {reference.records} of {reference.doubles}", file=sys.stderr)
            return 2
        stats = compare(reference, other, args.rel_tol, args.abs_tol, args.record_rel, args.skip)
        total = len(reference.values)
        if stats["differing"] == 0:
            print(f"{other.name} vs {reference.name}: bit-identical ({reference.records} records of "
                  f"{reference.doubles} doubles)")
            continue
        exact = other.name in args.exact
        passed = not exact and stats["beyond_tolerance"] == 0
        print(f"{other.name} vs {reference.name}: {stats['differing']} of {total} values differ "
              f"(first at record {stats['first'][0]}, value {stats['first'][1]}); "
              f"max {stats['max_ulps']} ulps at {stats['max_ulps_at']}, "
              f"max abs {stats['max_abs']:.3e} at {stats['max_abs_at']}, "
              f"max rel {stats['max_rel']:.3e} at {stats['max_rel_at']}"
              + (f", max relative to its record's scale {stats['max_record_rel']:.3e} at "
                 f"{stats['max_record_rel_at']}" if args.record_rel > 0 else "")
              + (f"; {stats['nan_mismatch']} NaN mismatches" if stats["nan_mismatch"] else "")
              + (" -> FAIL (must be bit-identical)" if exact else
                 f" -> {'pass' if passed else 'FAIL'} (rel_tol {args.rel_tol:g}, abs_tol {args.abs_tol:g}, "
                 f"record_rel {args.record_rel:g}"
                 + ("" if passed else f", {stats['beyond_tolerance']} values beyond") + ")"))
        print("  differing values by index in the record: "
              + ", ".join(f"[{i}] {count}" for i, count in enumerate(stats["by_index"]) if count))
        if not passed:
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
