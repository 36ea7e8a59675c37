#!/bin/sh
# Prints one phase marker of a `make` run (install, configure, build, tests, gates, ...): the wall
# time since the top-level make started and the CPU seconds (user + sys) its finished recipes used
# so far, read from that make's /proc entry, so that differences between markers are per phase.
# scripts/fresh-machine-test.sh reads these lines. Usage: make-phase.sh NAME START_EPOCH
name=$1
start=${2:-}
now=$(date +%s.%N)
# The make process is the nearest ancestor called make: recipe lines run under /bin/sh -c or
# directly, depending on the line, so $PPID alone may be a shell.
pid=$PPID
cpu=
while [ -n "$pid" ] && [ "$pid" -gt 1 ] && [ -r "/proc/$pid/stat" ]; do
  comm=$(cat "/proc/$pid/comm")
  if [ "$comm" = make ] || [ "$comm" = gmake ]; then
    # Fields after the ")" that ends the command name: 14 and 15 there are cutime and cstime
    # (stat fields 16 and 17), the CPU of the children make has waited for.
    ticks=$(getconf CLK_TCK 2>/dev/null || echo 100)
    cpu=$(sed 's/.*) //' "/proc/$pid/stat" | awk -v hz="$ticks" '{ printf "%.1f", ($14 + $15) / hz }')
    break
  fi
  pid=$(sed 's/.*) //' "/proc/$pid/stat" | awk '{ print $2 }')
done
elapsed=$(awk -v a="$start" -v b="$now" 'BEGIN { if (a == "") print "?"; else printf "%.1f", b - a }')
echo "make-phase: $name at $(date -u +%H:%M:%S) epoch $now elapsed ${elapsed} s cpu ${cpu:-?} s"
