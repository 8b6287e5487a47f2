#!/bin/bash
# Pack Granary, LIGGGHTS (when installed) and Open MPI's runtime with every
# library they load into one folder that runs on one x86-64 Linux machine
# without Debian's packages: for tools/scaling.sh on a borrowed many-core
# machine whose system has no Open MPI or LIGGGHTS.
#
#   tools/portable_bundle.sh [--out DIR] [--granary BUILD] [--no-liggghts] [--tar]
#
# DIR (default portable, in the current folder) gets bin/ (granary,
# liggghts, mpirun, orted), real/ (the executables), lib/ (their libraries,
# the dynamic loader and glibc included), ompi/ (Open MPI's plugins), share/
# (Open MPI's help texts) and an empty hwloc/ (no hwloc plugins). Each
# program in bin/ is a wrapper that starts the real one through the bundled
# loader with the bundled libraries only, so the other machine's C library
# does not matter, and sets Open MPI up for one machine: ranks started by
# mpirun itself (no ssh), a rank started without mpirun without a daemon,
# shared memory between the ranks. On the other machine (bash, and python3
# at /usr/bin/python3 for scaling.sh):
#
#   export PATH=$DIR/bin:$PATH
#   tools/scaling.sh --ranks 16,8,4,2,1 --liggghts --contention --granary $DIR/bin/granary
#
# With --tar also DIR.tar.xz (about 15 MB with LIGGGHTS). Needs Debian's
# openmpi-bin (orterun, orted and the plugins) and ldd.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out=portable
granary=$root/build/granary
liggghts=1
tarball=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out | --granary) [ $# -ge 2 ] || { echo "portable_bundle.sh: $1 needs a value" >&2; exit 2; } ;;
  esac
  case "$1" in
    --out) out=$2; shift 2 ;;
    --granary) granary=$2; shift 2 ;;
    --no-liggghts) liggghts=0; shift ;;
    --tar) tarball=1; shift ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed -n 's/^# \{0,1\}//p'; exit 0 ;;
    *) echo "portable_bundle.sh: unknown option '$1'; see tools/portable_bundle.sh --help" >&2; exit 2 ;;
  esac
done
# an existing DIR is replaced only when it is a bundle
if [ -e "$out" ] && [ ! -x "$out/real/granary" ]; then
  echo "portable_bundle.sh: $out exists and is not a bundle made by this script; choose another --out" >&2
  exit 2
fi
[ -x "$granary" ] || { echo "portable_bundle.sh: no Granary executable at $granary (build it, or pass --granary)" >&2; exit 2; }
ompi=/usr/lib/x86_64-linux-gnu/openmpi/lib/openmpi3
for f in /usr/bin/orterun /usr/bin/orted "$ompi"; do
  [ -e "$f" ] || { echo "portable_bundle.sh: $f is missing (install openmpi-bin)" >&2; exit 2; }
done
if [ "$liggghts" = 1 ] && ! command -v liggghts > /dev/null; then
  echo "portable_bundle.sh: no liggghts on PATH: the bundle holds Granary only" >&2
  liggghts=0
fi

# a fresh folder next to the old one, moved into place at the end
mkdir -p "$(dirname "$out")"
tmp=$(mktemp -d "${out%/}.tmp.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp"/{bin,real,lib,ompi,share,hwloc}
cp "$granary" "$tmp/real/granary"
cp /usr/bin/orterun "$tmp/real/orterun"
cp /usr/bin/orted "$tmp/real/orted"
programs="granary mpirun orted"
if [ "$liggghts" = 1 ]; then
  cp "$(readlink -f "$(command -v liggghts)")" "$tmp/real/liggghts"
  programs="$programs liggghts"
fi
cp "$ompi"/*.so "$tmp/ompi/"
if [ -d /usr/share/openmpi ]; then cp -r /usr/share/openmpi "$tmp/share/"; fi
# every library the executables and plugins load, and the loader
{ for f in "$tmp/real/"* "$tmp/ompi/"*.so; do if [ -e "$f" ]; then ldd "$f" || true; fi; done; } 2> /dev/null |
  awk '$3 ~ /^\// { print $3 } $1 ~ /^\/.*ld-linux/ { print $1 }' | sort -u |
  while read -r lib; do cp -L "$lib" "$tmp/lib/"; done
cp -L /lib64/ld-linux-x86-64.so.2 "$tmp/lib/"
for p in $programs; do
  real=$p
  [ "$p" = mpirun ] && real=orterun
  cat > "$tmp/bin/$p" << EOF
#!/bin/bash
# $p of the portable bundle (tools/portable_bundle.sh)
B=\$(cd "\$(dirname "\${BASH_SOURCE[0]}")/.." && pwd)
export PATH=\$B/bin:\$PATH
export OMPI_MCA_mca_base_component_path=\$B/ompi
export OMPI_MCA_mca_base_component_show_load_errors=0 OPAL_PKGDATADIR=\$B/share/openmpi
# PMIx and hwloc with their built-in components only (their plugins would
# come from the system's folders and pull in the system's libraries)
export PMIX_MCA_mca_base_component_disable_dlopen=1 HWLOC_PLUGINS_PATH=\$B/hwloc
# one machine: the ranks started by mpirun itself (no ssh), no daemon for a
# rank started alone, shared memory between the ranks without cross-process
# reads (which sandboxed kernels refuse)
export OMPI_MCA_plm=isolated OMPI_MCA_ess_singleton_isolated=1 OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_orte_launch_agent=\$B/bin/orted
exec "\$B/lib/ld-linux-x86-64.so.2" --library-path "\$B/lib" "\$B/real/$real" "\$@"
EOF
  chmod +x "$tmp/bin/$p"
done
rm -rf "$out"
mv "$tmp" "$out"
trap - EXIT
if [ "$tarball" = 1 ]; then
  tar -C "$(dirname "$out")" -cJf "$out.tar.xz.tmp" "$(basename "$out")"
  mv "$out.tar.xz.tmp" "$out.tar.xz"
fi
echo "portable_bundle.sh: $(du -sh "$out" | cut -f1) in $out ($programs)$([ "$tarball" = 1 ] && echo ", $(du -sh "$out.tar.xz" | cut -f1) in $out.tar.xz")"
