# The examples' tables agree (the full-order sweep, 4 columns, then the JP sweep with e*_1,
# 5 columns): same rows, numbers equal to 1e-9 relative (an e*_1 below 1e-9 is round-off).
# Input: the two tables' rows side by side, tab-separated, comment lines removed:
#   paste <(grep -v '^#' c.txt) <(grep -v '^#' f90.txt) | awk -F'\t' -v a=C -v b=Fortran -f same-table.awk
{ nc = split($1, c, " "); nf = split($2, f, " ") }
nc != nf || nc < 4 || nc > 5 { print "row shape differs: " $0; bad = 1; exit 1 }
{ for (i = 1; i <= nc; i++) { x = c[i]; y = f[i]; d = x - y; if (d < 0) d = -d; s = (x < 0 ? -x : x);
    if (i == 5 && s < 1e-9 && (y < 0 ? -y : y) < 1e-9) continue;   # e*_1 at round-off
    if (d > 1e-9 * s + 1e-300) { print a " and " b " differ: " $0; bad = 1; exit 1 } } n[nc]++ }
END { if (bad) exit 1; if (n[4] < 20 || n[5] < 20) { print "too few points: " n[4] " full-order, " n[5] " JP"; exit 1 }
      print n[4] " full-order and " n[5] " JP rows agree between " a " and " b }
