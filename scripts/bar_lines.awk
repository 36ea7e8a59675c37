# Turns each state row of an elastic_bar series (columns q_0 ... of the free nodes, clamped face
# x = 0 removed, node order z, y, x) into polylines for gnuplot: the longitudinal node lines and
# the cross-section outlines, one data set (two blank lines) per row. Used by elastic_bar.gp
# (with -v OFS=, to match the comma separator of scripts/common.gp).
/^#/ { next }
!header {
  for (c = 1; c <= NF; ++c) if ($c == "q_0") q0 = c
  header = 1
  next
}
{
  for (iz = 0; iz <= nz; ++iz) {
    for (iy = 0; iy <= ny; ++iy) {
      print 0, iy * hy, iz * hz
      for (ix = 1; ix <= nx; ++ix) node(ix, iy, iz)
      print ""
    }
  }
  for (ix = 1; ix <= nx; ++ix) {
    for (iy = 0; iy <= ny; ++iy) node(ix, iy, 0)
    for (iz = 1; iz <= nz; ++iz) node(ix, ny, iz)
    for (iy = ny - 1; iy >= 0; --iy) node(ix, iy, nz)
    for (iz = nz - 1; iz >= 0; --iz) node(ix, 0, iz)
    print ""
  }
  print ""
  print ""
}
function node(ix, iy, iz,    f) {
  f = (ix - 1) + nx * (iy + (ny + 1) * iz)
  print $(q0 + 3 * f), $(q0 + 3 * f + 1), $(q0 + 3 * f + 2)
}
