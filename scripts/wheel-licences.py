"""Puts the licence texts into a repaired wheel: ffsr's LICENSE, and for every shared library auditwheel
copied into ffsr.libs/ the copyright file of the Debian package it came from, with an index that names
library, package and version. Rewrites the wheel in place, its RECORD with the new files' hashes.

Usage: wheel-licences.py WHEEL LICENSE
"""

import base64
import hashlib
import os
import re
import subprocess
import sys
import zipfile

LIB_DIRS = ("/usr/lib/x86_64-linux-gnu", "/lib/x86_64-linux-gnu", "/usr/lib", "/lib",
            "/usr/lib/x86_64-linux-gnu/openblas-pthread")  # OpenBLAS, the BLAS of IPOPT's MUMPS


def fail(message: str) -> None:
    sys.exit(f"wheel-licences.py: {message}")


def original_name(grafted: str) -> str:
    """auditwheel names a copied library <stem>-<8 hex digits of its hash><rest>, the stem the name up to
    its first dot (libblas.so.3: libblas-<hash>.so.3; libdmumps_seq-5.5.0.so: libdmumps_seq-5-<hash>.5.0.so)."""
    m = re.fullmatch(r"(.+)-[0-9a-f]{8}(\..*)", grafted)
    if not m:
        fail(f"ffsr.libs/{grafted}: not a name auditwheel gives (<name>-<hash>.<rest>)")
    return m.group(1) + m.group(2)


def debian_package(library: str) -> tuple:
    """The Debian package (name, version) that installed the library named `library`."""
    for d in LIB_DIRS:
        path = os.path.join(d, library)
        if os.path.exists(path):
            for candidate in (path, os.path.realpath(path)):
                r = subprocess.run(["dpkg-query", "-S", candidate], capture_output=True, text=True)
                if r.returncode == 0:
                    package = r.stdout.split(":")[0].strip()
                    v = subprocess.run(["dpkg-query", "-W", "-f=${Version}", package], capture_output=True,
                                       text=True, check=True).stdout.strip()
                    return package, v
    fail(f"{library}: no Debian package installed it (looked in {', '.join(LIB_DIRS)})")
    return "", ""


def record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def main() -> None:
    if len(sys.argv) != 3:
        fail("usage: wheel-licences.py WHEEL LICENSE")
    wheel, licence = sys.argv[1], sys.argv[2]
    with zipfile.ZipFile(wheel) as z:
        entries = [(i, z.read(i.filename)) for i in z.infolist()]
    names = [i.filename for i, _ in entries]
    dist_info = sorted({n.split("/")[0] for n in names if n.split("/")[0].endswith(".dist-info")})
    if len(dist_info) != 1:
        fail(f"{wheel}: expected one .dist-info folder, found {dist_info}")
    dist_info = dist_info[0]
    grafted = sorted(n.split("/", 1)[1] for n in names if n.startswith("ffsr.libs/") and n != "ffsr.libs/")
    if not grafted:
        fail(f"{wheel}: no ffsr.libs/: run it on the wheel auditwheel repaired")
    added = {}
    with open(licence, "rb") as f:
        added[f"{dist_info}/licenses/LICENSE"] = f.read()
    index = ["The shared libraries in ffsr.libs/, from Debian 12 packages; each keeps its own licence, given",
             "in the package's copyright file beside this index.", ""]
    for g in grafted:
        package, version = debian_package(original_name(g))
        copyright_file = f"/usr/share/doc/{package}/copyright"
        if not os.path.isfile(copyright_file):
            fail(f"{copyright_file}: missing (the licence of ffsr.libs/{g})")
        with open(copyright_file, "rb") as f:
            added[f"{dist_info}/licenses/{package}.copyright"] = f.read()
        index.append(f"ffsr.libs/{g}: Debian package {package} {version}, licenses/{package}.copyright")
    added[f"{dist_info}/licenses/bundled-libraries.txt"] = ("\n".join(index) + "\n").encode()
    record = f"{dist_info}/RECORD"
    kept = [(i, d) for i, d in entries if i.filename != record and i.filename not in added]
    lines = [record_line(i.filename, d) for i, d in kept if not i.filename.endswith("/")]
    lines += [record_line(n, d) for n, d in added.items()]
    lines.append(f"{record},,")
    tmp = wheel + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for i, d in kept:
            z.writestr(i, d)
        for n, d in added.items():
            z.writestr(n, d)
        z.writestr(record, "\n".join(lines) + "\n")
    os.replace(tmp, wheel)
    print(f"wheel-licences.py: {len(added)} licence files into {os.path.basename(wheel)} "
          f"({len(grafted)} bundled libraries)")


if __name__ == "__main__":
    main()
