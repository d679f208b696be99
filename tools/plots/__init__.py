"""The plots of tools/muflow_plot.py, one module per concern:

  run.py       a run folder read once: summary.ini, case keys, CSV files,
               field files, the case's reference data
  units.py     axis labels in the case's units (SI or the scene's scales)
  figure.py    figure sizes from a box's aspect, saving, body outlines
  fields.py    field.png: any dataset of a field file over a plane
  history.py   history.png: steady convergence or a transient's time series
  scenes.py    compare.png: each scene's comparison with its reference,
               dispatching to profile.py, cavity.py, heap.py, duct.py,
               collapse.py and cylinder.py
"""
