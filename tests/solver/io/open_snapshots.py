"""Open a capsim case's snapshots with ParaView's own XDMF reader and render one image offscreen.

Run by pvbatch (tests/solver/io/snapshot_paraview.cc):
    pvbatch open_snapshots.py CASE_DIR NUM_NODES NUM_ELEMENTS PNG
Checks, against the HDF5 file read independently with h5py (not through the .xmf being tested):
  - the time steps ParaView sees are the snapshot times stored in case.h5;
  - every time step has NUM_NODES points and NUM_ELEMENTS quadratic triangles (XDMF Triangle_6) or
    4 * NUM_ELEMENTS flat ones (the linear split), whichever topology the .xmf declares;
  - the point arrays q_n, q (3 components), velocity (3), tau_min and tau_max exist and are finite;
then renders the surface coloured by q_n into PNG and checks that the image is not blank. Prints one line per failure and exits 1 on any.
"""
import math
import os
import sys

import h5py
from paraview import simple as pv
from paraview import servermanager as sm

case_dir, num_nodes, num_elements, png = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message, flush=True)


with h5py.File(os.path.join(case_dir, "case.h5"), "r") as f:
    stored_times = sorted(float(g.attrs["t"]) for g in f["snapshots"].values())
check(len(stored_times) >= 2, "case.h5 holds %d snapshots, the case file asks for several" % len(stored_times))

reader = pv.XDMFReader(registrationName="case", FileNames=[os.path.join(case_dir, "case.xmf")])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues) if reader.TimestepValues is not None else []
if not isinstance(times, list):
    times = [times]
check(len(times) == len(stored_times), "ParaView sees %d time steps, case.h5 has %d" % (len(times), len(stored_times)))
check(all(abs(a - b) <= 1e-9 * max(1.0, abs(b)) for a, b in zip(times, stored_times)),
      "time values differ: ParaView %s, case.h5 %s" % (times, stored_times))

point_arrays = {"q_n": 1, "q": 3, "velocity": 3, "tau_min": 1, "tau_max": 1}
VTK_TRIANGLE, VTK_QUADRATIC_TRIANGLE = 5, 22
for t in times:
    reader.UpdatePipeline(t)
    data = sm.Fetch(reader)
    if data.IsA("vtkMultiBlockDataSet") or data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        data = it.GetCurrentDataObject()
    check(data.GetNumberOfPoints() == num_nodes,
          "t = %g: %d points, expected %d" % (t, data.GetNumberOfPoints(), num_nodes))
    cell_types = {data.GetCellType(i) for i in range(data.GetNumberOfCells())}
    expected_cells = num_elements if cell_types == {VTK_QUADRATIC_TRIANGLE} else 4 * num_elements
    check(cell_types in ({VTK_QUADRATIC_TRIANGLE}, {VTK_TRIANGLE}), "t = %g: cell types %s" % (t, cell_types))
    check(data.GetNumberOfCells() == expected_cells,
          "t = %g: %d cells, expected %d" % (t, data.GetNumberOfCells(), expected_cells))
    pd = data.GetPointData()
    for name, components in point_arrays.items():
        a = pd.GetArray(name)
        check(a is not None, "t = %g: point array %s missing (have %s)"
              % (t, name, [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())]))
        if a is None:
            continue
        check(a.GetNumberOfComponents() == components,
              "t = %g: %s has %d components, expected %d" % (t, name, a.GetNumberOfComponents(), components))
        check(a.GetNumberOfTuples() == num_nodes, "t = %g: %s has %d tuples" % (t, name, a.GetNumberOfTuples()))
        lo, hi = a.GetRange(-1)
        check(math.isfinite(lo) and math.isfinite(hi), "t = %g: %s is not finite (%g, %g)" % (t, name, lo, hi))

# One image, offscreen: the last snapshot coloured by the normal load.
view = pv.CreateRenderView()
view.ViewSize = [400, 300]
view.OrientationAxesVisibility = 0
if hasattr(view, "UseColorPaletteForBackground"):  # ParaView ≥ 5.10 takes the palette's colour otherwise
    view.UseColorPaletteForBackground = 0
view.Background = [1.0, 1.0, 1.0]
view.ViewTime = times[-1] if times else 0.0
display = pv.Show(reader, view)
pv.ColorBy(display, ("POINTS", "q_n"))
display.RescaleTransferFunctionToDataRange(True)
view.ResetCamera()
pv.SaveScreenshot(png, view, ImageResolution=[400, 300])
check(os.path.isfile(png) and os.path.getsize(png) > 0, "no image written to " + png)
if os.path.isfile(png):
    # Not blank: enough pixels differ from the background, taken from a corner pixel (whatever colour the
    # view's palette gave it), i.e. the capsule was drawn.
    from vtkmodules.vtkIOImage import vtkPNGReader
    image = vtkPNGReader()
    image.SetFileName(png)
    image.Update()
    pixels = image.GetOutput().GetPointData().GetScalars()
    n = pixels.GetNumberOfTuples()
    background = pixels.GetTuple(0)[:3]
    drawn = sum(1 for i in range(n) if max(abs(a - b) for a, b in zip(pixels.GetTuple(i)[:3], background)) > 8)
    check(0.01 * n < drawn < 0.99 * n, "the image is blank or uniform: %d of %d pixels drawn" % (drawn, n))

if failures:
    sys.exit(1)
print("ok: %d time steps, %d points" % (len(times), num_nodes))
