#!/usr/bin/python3
# Renders the airway wall of a naris solve coloured by the wall shear stress, seen from the
# patient's right (LPS: from −x), into a PNG. Run through scripts/figures (headless, Xvfb).
# Usage: render_wall_shear.py SOLUTION_FOLDER OUT.png CAPTION
import sys, vtk
folder, out, caption = sys.argv[1], sys.argv[2], sys.argv[3]
bnd = vtk.vtkXMLPolyDataReader(); bnd.SetFileName(folder + "/boundary.vtp"); bnd.Update()
s = bnd.GetOutput(); b = s.GetBounds()
arr = s.GetCellData().GetArray("wall_shear_stress_magnitude")
s.GetCellData().SetActiveScalars("wall_shear_stress_magnitude")
hi = sorted(arr.GetValue(i) for i in range(arr.GetNumberOfTuples()))[int(0.99 * arr.GetNumberOfTuples())]
lut = vtk.vtkLookupTable(); lut.SetHueRange(0.667, 0.0); lut.SetTableRange(0, hi); lut.Build()
m = vtk.vtkPolyDataMapper(); m.SetInputData(s); m.SetScalarModeToUseCellData(); m.SetScalarRange(0, hi); m.SetLookupTable(lut)
a = vtk.vtkActor(); a.SetMapper(m)
bar = vtk.vtkScalarBarActor(); bar.SetLookupTable(lut); bar.SetTitle("wall shear stress (Pa)"); bar.SetNumberOfLabels(5)
bar.SetWidth(0.1); bar.SetHeight(0.6); bar.SetPosition(0.87, 0.2); bar.UnconstrainedFontSizeOn()
for t in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
    t.SetColor(0, 0, 0); t.SetFontSize(14); t.ItalicOff(); t.ShadowOff(); t.BoldOff()
ren = vtk.vtkRenderer(); ren.SetBackground(1, 1, 1); ren.AddActor(a); ren.AddActor2D(bar)
c = ((b[0]+b[1])/2, (b[2]+b[3])/2, (b[4]+b[5])/2)
cam = ren.GetActiveCamera(); cam.SetFocalPoint(*c); cam.SetPosition(c[0] - 300, c[1], c[2]); cam.SetViewUp(0, 0, 1)
ren.ResetCamera(); cam.Zoom(1.45)
txt = vtk.vtkTextActor(); txt.SetInput(caption); txt.GetTextProperty().SetColor(0, 0, 0); txt.GetTextProperty().SetFontSize(15); txt.SetPosition(12, 12)
ren.AddActor2D(txt)
w = vtk.vtkRenderWindow(); w.SetOffScreenRendering(1); w.AddRenderer(ren); w.SetSize(1100, 520); w.SetMultiSamples(8); w.Render()
f = vtk.vtkWindowToImageFilter(); f.SetInput(w); f.Update()
png = vtk.vtkPNGWriter(); png.SetFileName(out); png.SetInputConnection(f.GetOutputPort()); png.Write()
print("wrote", out, "scale to", hi)
