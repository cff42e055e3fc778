#!/usr/bin/env bash
# Adds Debian's Open MPI runtime to .gpu-bundle/ (scripts/gpu-bundle.sh first), for the GPU
# machine, which has no Debian packages: mpirun (orterun), the MCA components of Open MPI
# and PMIx, their help texts and parameter files, lucent-ranks-bench, and every library
# they load. On that machine: `.gpu-bundle/mpirun -np 4 .gpu-bundle/run .gpu-bundle/bin/lucent
# render ...` (the wrapper points Open MPI and PMIx at the bundle: OPAL_* and *_MCA_*).
set -euo pipefail
cd "$(dirname "$0")/.."
out=.gpu-bundle
build=${LUCENT_BUNDLE_BUILD:-build}
[ -x "$out/run" ] || { echo "gpu-bundle-mpi: run scripts/gpu-bundle.sh first" >&2; exit 1; }
cmake --build "$build" --target lucent_ranks_bench > /dev/null
ompi=$out/openmpi
rm -rf "$ompi"
mkdir -p "$ompi/bin" "$ompi/lib" "$ompi/share" "$ompi/etc"
cp -L /usr/bin/orterun "$ompi/bin/mpirun"
cp -L /usr/bin/orted "$ompi/bin/orted"
cp "$build/lucent-ranks-bench" "$out/bin/"
cp -rL /usr/lib/x86_64-linux-gnu/openmpi/lib/openmpi3 "$ompi/lib/openmpi3"
cp -rL /usr/lib/x86_64-linux-gnu/pmix2/lib/pmix "$ompi/lib/pmix"
cp -rL /usr/share/openmpi "$ompi/share/openmpi"
cp -rL /usr/lib/x86_64-linux-gnu/pmix2/share/pmix "$ompi/share/pmix"
cp -L /etc/openmpi/openmpi-mca-params.conf "$ompi/etc/"
[ -d /usr/lib/x86_64-linux-gnu/hwloc ] && cp -rL /usr/lib/x86_64-linux-gnu/hwloc "$ompi/lib/hwloc"
# Every library the runtime, its components and the MPI programs load (the bundled loader
# resolves them from lib/, as for the other programs).
for f in "$ompi"/bin/* "$ompi"/lib/openmpi3/*.so "$ompi"/lib/pmix/*.so "$out"/bin/lucent-ranks-bench \
         "$out"/bin/lucent; do
  ldd "$f" 2>/dev/null | awk '/=>/ && $3 ~ /^\// {print $3}'
done | sort -u | while read -r lib; do cp -Ln "$lib" "$out/lib/" 2>/dev/null || true; done
strip --strip-unneeded "$out/bin/lucent-ranks-bench" "$ompi"/bin/* 2>/dev/null || true
cat > "$out/mpirun" <<'RUN'
#!/bin/sh
# mpirun from the bundle: Open MPI and PMIx find their components, help texts and
# parameters here, and run as root in the GPU machine's container.
here=$(cd "$(dirname "$0")" && pwd)
o=$here/openmpi
export OPAL_PREFIX=$o OPAL_EXEC_PREFIX=$o OPAL_BINDIR=$o/bin OPAL_LIBDIR=$o/lib \
       OPAL_PKGLIBDIR=$o/lib/openmpi3 OPAL_DATAROOTDIR=$o/share OPAL_DATADIR=$o/share \
       OPAL_PKGDATADIR=$o/share/openmpi OPAL_SYSCONFDIR=$o/etc
export OMPI_MCA_mca_base_component_path=$o/lib/openmpi3
export PMIX_INSTALL_PREFIX=$o PMIX_MCA_mca_base_component_path=$o/lib/pmix
export PMIX_MCA_pinstalldirs_env_pkgdatadir=$o/share/pmix
export HWLOC_PLUGINS_PATH=$o/lib/hwloc
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# One node: no ssh, and no single-copy shared memory (a container may forbid ptrace's CMA).
export OMPI_MCA_plm=isolated OMPI_MCA_btl_vader_single_copy_mechanism=none
exec "$here/run" "$o/bin/mpirun" "$@"
RUN
chmod +x "$out/mpirun"
du -sh "$out"
