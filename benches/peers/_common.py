"""Shared helpers of the peer benchmark scripts: timing and the result table."""

import statistics
import time


def best_time(fn, repeat=5, warmup=1):
    """Median wall-clock seconds of ``fn()`` over ``repeat`` runs after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def print_table(title, rows):
    """Prints rows of (workload, ours_s, peer_name, peer_s) with the ratio peer/ours."""
    print(f"{title}")
    print(f"{'workload':<36} {'ours (s)':>10} {'peer':<28} {'peer (s)':>10} {'ratio':>7}")
    for workload, ours, peer_name, peer in rows:
        print(f"{workload:<36} {ours:>10.4f} {peer_name:<28} {peer:>10.4f} {peer / ours:>7.3f}")


def vtk_fixed_point_window(vol_u8, tf_points, size, spacing=(1.0, 1.0, 1.0), shade=None,
                           sample_distance=0.5):
    """An off-screen VTK render window with ``vtkFixedPointVolumeRayCastMapper`` on a uint8
    ``[z, y, x]`` volume: ``tf_points`` are ``(density, r, g, b, opacity)`` rows (opacity per
    unit length), trilinear interpolation, fixed sample distance, full image resolution;
    ``shade`` = ``(ambient, diffuse, specular, power)`` turns on VTK's gradient shading.
    Returns ``(window, renderer)``; set the camera on the renderer, then ``window.Render()``.
    """
    import vtk
    from vtk.util import numpy_support

    img = vtk.vtkImageData()
    nz, ny, nx = vol_u8.shape
    img.SetDimensions(nx, ny, nz)
    img.SetSpacing(*spacing)
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(
        vol_u8.ravel(), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR))
    ctf, otf = vtk.vtkColorTransferFunction(), vtk.vtkPiecewiseFunction()
    for d, r, g, b, a in tf_points:
        ctf.AddRGBPoint(d, r, g, b)
        otf.AddPoint(d, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetInterpolationTypeToLinear()
    prop.SetScalarOpacityUnitDistance(1.0)
    if shade is not None:
        prop.ShadeOn()
        prop.SetAmbient(shade[0])
        prop.SetDiffuse(shade[1])
        prop.SetSpecular(shade[2])
        prop.SetSpecularPower(shade[3])
    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(img)
    mapper.AutoAdjustSampleDistancesOff()
    mapper.SetSampleDistance(sample_distance)
    mapper.SetImageSampleDistance(1.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(ren)
    win.SetSize(size, size)
    return win, ren
