#!/usr/bin/python3
"""Reads grainlab's VTK XML files with VTK's own readers (Debian's python3-vtk9) and checks
them against the expectations a grainlab test wrote, one per line:

  open FILE vtu|vti NPOINTS NCELLS      the file opens without a VTK error, with these counts
  coord FILE I C VALUE                  component C of point I's coordinates
  point|cell|field FILE NAME I C VALUE  component C of tuple I of a point/cell/field array
  near point|cell FILE NAME I C VALUE ATOL   the same within ATOL
  near coord FILE I C VALUE ATOL        a point coordinate within ATOL
  sum coord FILE I0 I1 VALUE RTOL       x + y + z of each point I0..I1 (a plane's points)
  ncomp point|cell FILE NAME N          the array exists with N components
  type point|cell FILE NAME VTKTYPE     its VTK data type name (Float64, Int64, ...)
  celltype FILE I TYPE                  cell I's VTK cell type
  cellpoints FILE I P0 P1 ...           cell I's point ids
  sum point|cell FILE NAME C VALUE RTOL the sum of component C over all tuples
  image FILE NX NY NZ OX OY OZ SX SY SZ dimensions, origin and spacing of an image
  pvd FILE N T1 F1 ... TN FN            a collection of N data sets (timestep, file), in order,
                                        each of which opens with VTK
  absent FILE                           the file does not exist

VALUE is printed with %.17g by grainlab and compared exactly (Float64 arrays round-trip).
Prints one line per failed expectation and exits 1 if any failed.

  /usr/bin/python3 vtk_read.py DIR EXPECTATIONS
"""
import os
import sys
import xml.etree.ElementTree as ET

try:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy  # noqa: F401  (numpy comes with it)
except ImportError as e:
    print("FAIL: cannot import VTK's Python module (%s): apt-get install python3-vtk9, and run "
          "Debian's /usr/bin/python3" % e)
    sys.exit(1)

base = sys.argv[1]
failures = []
checked = 0
cache = {}


class ErrorCatcher:
    def __init__(self):
        self.messages = []

    def __call__(self, obj, event):
        self.messages.append(event)


def read(name):
    if name in cache:
        return cache[name]
    path = os.path.join(base, name)
    if not os.path.exists(path):
        raise RuntimeError("%s does not exist" % name)
    if name.endswith(".vti"):
        r = vtk.vtkXMLImageDataReader()
    else:
        r = vtk.vtkXMLUnstructuredGridReader()
    catcher = ErrorCatcher()
    r.AddObserver("ErrorEvent", catcher)
    r.AddObserver("WarningEvent", catcher)
    r.SetFileName(path)
    r.Update()
    if catcher.messages or r.GetErrorCode():
        raise RuntimeError("VTK reported %s reading %s (error code %d)"
                           % (catcher.messages, name, r.GetErrorCode()))
    cache[name] = r.GetOutput()
    return cache[name]


def array(ds, where, name):
    data = {"point": ds.GetPointData(), "cell": ds.GetCellData(),
            "field": ds.GetFieldData()}[where]
    a = data.GetAbstractArray(name)
    if a is None:
        have = [data.GetArrayName(k) for k in range(data.GetNumberOfArrays())]
        raise RuntimeError("no %s array '%s' (have %s)" % (where, name, have))
    return a


def number(s):
    return float(s) if any(c in s for c in ".eEn") else int(s)


def check(cond, line, msg):
    global checked
    checked += 1
    if not cond:
        failures.append("%s: %s" % (line, msg))


for raw in open(sys.argv[2]):
    line = raw.strip()
    if not line:
        continue
    w = line.split()
    try:
        op = w[0]
        if op == "open":
            ds = read(w[1])
            check(ds.GetNumberOfPoints() == int(w[3]) and ds.GetNumberOfCells() == int(w[4]),
                  line, "points %d, cells %d" % (ds.GetNumberOfPoints(), ds.GetNumberOfCells()))
            want = "vtkImageData" if w[2] == "vti" else "vtkUnstructuredGrid"
            check(ds.GetClassName() == want, line, ds.GetClassName())
        elif op == "coord":
            ds = read(w[1])
            got = ds.GetPoint(int(w[2]))[int(w[3])]
            check(got == float(w[4]), line, "got %r" % got)
        elif op in ("point", "cell", "field"):
            a = array(read(w[1]), op, w[2])
            got = a.GetComponent(int(w[3]), int(w[4]))
            want = number(w[5])
            check(got == want or (want != want and got != got), line, "got %r" % got)
        elif op == "near" and w[1] == "coord":
            got = read(w[2]).GetPoint(int(w[3]))[int(w[4])]
            check(abs(got - float(w[5])) <= float(w[6]), line, "got %r" % got)
        elif op == "sum" and w[1] == "coord":
            ds = read(w[2])
            want = float(w[5])
            for k in range(int(w[3]), int(w[4]) + 1):
                got = sum(ds.GetPoint(k))
                check(abs(got - want) <= float(w[6]) * abs(want), line, "point %d: %r" % (k, got))
        elif op == "near":
            a = array(read(w[2]), w[1], w[3])
            got = a.GetComponent(int(w[4]), int(w[5]))
            check(abs(got - float(w[6])) <= float(w[7]), line, "got %r" % got)
        elif op == "ncomp":
            a = array(read(w[2]), w[1], w[3])
            check(a.GetNumberOfComponents() == int(w[4]), line,
                  "got %d components" % a.GetNumberOfComponents())
        elif op == "type":
            a = array(read(w[2]), w[1], w[3])
            names = {vtk.VTK_DOUBLE: "Float64", vtk.VTK_LONG_LONG: "Int64", vtk.VTK_LONG: "Int64",
                     vtk.VTK_ID_TYPE: "Int64", vtk.VTK_INT: "Int32",
                     vtk.VTK_UNSIGNED_CHAR: "UInt8"}
            got = names.get(a.GetDataType(), a.GetDataTypeAsString())
            check(got == w[4], line, "got %s" % got)
        elif op == "celltype":
            got = read(w[1]).GetCellType(int(w[2]))
            check(got == int(w[3]), line, "got %d" % got)
        elif op == "cellpoints":
            ids = read(w[1]).GetCell(int(w[2])).GetPointIds()
            got = [ids.GetId(k) for k in range(ids.GetNumberOfIds())]
            check(got == [int(x) for x in w[3:]], line, "got %s" % got)
        elif op == "sum":
            a = array(read(w[2]), w[1], w[3])
            c = int(w[4])
            total = sum(a.GetComponent(k, c) for k in range(a.GetNumberOfTuples()))
            want = float(w[5])
            check(abs(total - want) <= float(w[6]) * abs(want), line, "got %r" % total)
        elif op == "image":
            ds = read(w[1])
            got = list(ds.GetDimensions()) + list(ds.GetOrigin()) + list(ds.GetSpacing())
            want = [int(x) for x in w[2:5]] + [float(x) for x in w[5:11]]
            check(got == want, line, "got %s" % got)
        elif op == "pvd":
            root = ET.parse(os.path.join(base, w[1])).getroot()
            check(root.tag == "VTKFile" and root.get("type") == "Collection", line,
                  "not a VTK Collection")
            sets = root.findall("./Collection/DataSet")
            n = int(w[2])
            check(len(sets) == n, line, "got %d data sets" % len(sets))
            for k, d in enumerate(sets[:n]):
                t, f = float(w[3 + 2 * k]), w[4 + 2 * k]
                check(float(d.get("timestep")) == t and d.get("file") == f, line,
                      "data set %d is (%s, %s)" % (k + 1, d.get("timestep"), d.get("file")))
                ds = read(os.path.join(os.path.dirname(w[1]), d.get("file")))
                check(ds.GetNumberOfPoints() >= 0, line, "unreadable")
        elif op == "absent":
            check(not os.path.exists(os.path.join(base, w[1])), line, "exists")
        else:
            failures.append("%s: unknown expectation" % line)
    except Exception as e:  # a missing array or file fails the line, not the whole run
        failures.append("%s: %s" % (line, e))

for f in failures:
    print("FAIL " + f)
print("%d checks, %d failed" % (checked, len(failures)))
sys.exit(1 if failures or checked == 0 else 0)
