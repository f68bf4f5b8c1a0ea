#!/bin/sh
# check_simd_symbols.sh OBJECT... — the per-instruction-set kernel objects
# (native/src/simd/kernel_*.cpp) define no external or weak symbol outside their
# own namespace cg::simd_<level>: the linker can then never hand one level's
# code (say AVX-512) to another level's or the baseline's caller.
status=0
found=0
for o in "$@"; do
  case "$o" in *kernel_*.o) ;; *) continue ;; esac
  found=$((found + 1))
  level=$(basename "$o" | sed -e 's/^kernel_//' -e 's/\.cpp\.o$//' -e 's/\.o$//')
  bad=$(nm -C --defined-only "$o" | awk '$2 ~ /^[A-Zuvw]$/' | grep -v "cg::simd_${level}::")
  if [ -n "$bad" ]; then
    echo "FAIL $o defines symbols outside cg::simd_${level}:"
    echo "$bad"
    status=1
  else
    count=$(nm -C --defined-only "$o" | awk '$2 ~ /^[A-Zuvw]$/' | wc -l)
    echo "ok   $o: $count external symbol(s), all in cg::simd_${level}"
  fi
done
[ "$found" -ge 1 ] || { echo "FAIL no kernel_*.o among the arguments"; exit 1; }
exit $status
