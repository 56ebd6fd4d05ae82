"""Writes the netCDF-4 (HDF5) grids of aeromag-grid's tests
(crates/grid/tests/data/*.nc) with the netCDF4 library (libnetcdf, as GMT 6
and xarray write them):

- nc4_packed.nc: 4 x 4 nodes (square: the axes are told apart by name), y
  descending, int16 packed with scale_factor/add_offset, deflated, one node
  at the _FillValue, a transverse_mercator grid mapping with epsg_code 32618;
- nc4_degrees.nc: 3 x 2 nodes in lon/lat degrees (refused: every grid
  computation takes its cell in metres).

    pip install netCDF4 numpy && python tools/reference/netcdf4_grids.py OUT_DIR
"""

import sys

import netCDF4
import numpy as np

out = sys.argv[1] if len(sys.argv) > 1 else "."

with netCDF4.Dataset(f"{out}/nc4_packed.nc", "w", format="NETCDF4") as ds:
    ds.createDimension("x", 4)
    ds.createDimension("y", 4)
    x = ds.createVariable("x", "f8", ("x",))
    y = ds.createVariable("y", "f8", ("y",))
    x[:] = 500_000.0 + 10.0 * np.arange(4)
    y[:] = 4_000_000.0 + 10.0 * np.arange(4)[::-1]
    x.units = y.units = "m"
    crs = ds.createVariable("crs", "i4", ())
    crs.grid_mapping_name = "transverse_mercator"
    crs.epsg_code = np.int32(32618)
    z = ds.createVariable("z", "i2", ("y", "x"), zlib=True, fill_value=np.int16(-32768))
    z.scale_factor = 0.5
    z.add_offset = 50_000.0
    z.units = "nT"
    z.long_name = "total magnetic intensity"
    z.grid_mapping = "crs"
    values = np.ma.masked_array(50_000.0 + 0.5 * np.arange(16).reshape(4, 4), mask=False)
    values.mask = np.zeros((4, 4), bool)
    values.mask[0, 0] = True
    z[:] = values
    ds.node_offset = np.int32(0)

with netCDF4.Dataset(f"{out}/nc4_degrees.nc", "w", format="NETCDF4") as ds:
    ds.createDimension("lon", 3)
    ds.createDimension("lat", 2)
    lon = ds.createVariable("lon", "f8", ("lon",))
    lat = ds.createVariable("lat", "f8", ("lat",))
    lon[:] = [-75.0, -74.99, -74.98]
    lat[:] = [45.0, 45.01]
    lon.units = "degrees_east"
    lat.units = "degrees_north"
    z = ds.createVariable("z", "f4", ("lat", "lon"))
    z[:] = np.zeros((2, 3), "f4")
