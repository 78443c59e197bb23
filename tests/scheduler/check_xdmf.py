# Checks an XDMF index against its HDF5 file: the XDMF parses as XML, and every dataset a
# DataItem names exists in the HDF5 file with the shape the DataItem declares (and the declared
# number type). Usage: check_xdmf.py FILE.xdmf; prints "ok <grids> <items>" or the first problem
# and exits 1. Debian's python3 with h5py (deploy/debian-packages.txt).
import os
import sys
import xml.etree.ElementTree as ET

import h5py

path = sys.argv[1]
root = ET.parse(path).getroot()
if root.tag != "Xdmf":
    sys.exit(f"{path}: root element {root.tag}, expected Xdmf")
items = root.iter("DataItem")
n_items = 0
files = {}
for item in items:
    n_items += 1
    if item.get("Format") != "HDF":
        sys.exit(f"{path}: DataItem with Format={item.get('Format')}, expected HDF")
    ref = item.text.strip()
    fname, dset = ref.split(":", 1)
    full = os.path.join(os.path.dirname(path), fname)
    if full not in files:
        files[full] = h5py.File(full, "r")
    f = files[full]
    if dset not in f:
        sys.exit(f"{path}: {ref}: no such dataset")
    want = tuple(int(x) for x in item.get("Dimensions").split())
    if f[dset].shape != want:
        sys.exit(f"{path}: {ref}: shape {f[dset].shape}, the XDMF says {want}")
    kind = {"Float": "f", "Int": "i"}[item.get("NumberType")]
    if f[dset].dtype.kind != kind or f[dset].dtype.itemsize != int(item.get("Precision")):
        sys.exit(f"{path}: {ref}: dtype {f[dset].dtype}, the XDMF says {item.get('NumberType')}{item.get('Precision')}")
grids = [g for g in root.iter("Grid") if g.get("GridType") == "Uniform"]
times = [float(t.get("Value")) for t in root.iter("Time")]
if times != sorted(times):
    sys.exit(f"{path}: times not increasing")
print("ok", len(grids), n_items, len(times))
