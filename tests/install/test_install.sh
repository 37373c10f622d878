#!/usr/bin/env bash
# phytocal as a C library (issue 15): the build installs into a prefix, and
# a program outside the tree (examples/embed) builds against the installed
# copy and fits what it should.
#
#   bash test_install.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# PATH/TO/phytocal is the command in the build directory (the build
# directory is its folder, or else the working directory).  The shared data
# folder is not used.  Steps:
#   1. cmake --install BUILD --prefix TMP/prefix
#   2. the files: library with its SONAME symlink, headers with their
#      folders, the umbrella header, phytocal.pc, the CMake package
#   3. readelf: SONAME libphytocal.so.0; only phc_* symbols exported
#   4. every installed header compiles alone as strict C11 and includes no
#      C++ or third-party header a consumer might lack (known exceptions
#      listed below, with the reason)
#   5. examples/embed configured with find_package(phytocal) and built; the
#      fitted delta's 95% interval holds the truth
#   6. embed.c compiled with `cc $(pkg-config --cflags --libs phytocal)` and
#      run with LD_LIBRARY_PATH; same check
#   7. a C++ program includes the umbrella header and links
#   8. the installed phytocal command runs (RUNPATH $ORIGIN/../lib)
#   9. the MPI module phytocal_mpi.so is installed beside the library, and
#      the installed command loads it from there under mpirun -np 2
#  10. the modules (phytocal_{ceres,photo,mesh,netcdf}.so) are installed
#      beside the library; `phytocal version` loads none of them nor their
#      libraries; the installed command's fit of the enzyme example loads the
#      installed Ceres module; a program built with pkg-config writes and
#      reads a PNG and queries a one-triangle mesh through the installed
#      photo and mesh modules; with PHYTOCAL_MODULE_DIR naming an empty
#      folder the same calls fail with PHC_ERR_IO naming the module and path
# Prints "ok - <step>" / "not ok - <step>: <why>", then "N passed, M failed";
# exits 1 if any step failed, 77 (skip) in a sanitizer build (a program
# built without -fsanitize cannot load a sanitized library).

set -u
PHC=${1:-}
if [ -z "$PHC" ]; then
    echo "usage: bash test_install.sh PATH/TO/phytocal [SHARED_DATA_DIR]" >&2
    exit 2
fi
case "$PHC" in /*) ;; *) PHC="$PWD/$PHC" ;; esac
# The checkout this script belongs to (physical path: the README checker
# runs it through a symlinked tests/).
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd -P)
BUILD=$(cd "$(dirname "$PHC")" 2>/dev/null && pwd -P)
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
    BUILD=$(pwd -P)
fi
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
    echo "not ok - setup: no CMakeCache.txt next to $PHC nor in $PWD: run this from the build directory"
    echo "0 passed, 1 failed"
    exit 1
fi
if grep -q '^PHC_SANITIZE:BOOL=ON' "$BUILD/CMakeCache.txt"; then
    echo "skip: $BUILD is a sanitizer build (PHC_SANITIZE=ON): programs built without -fsanitize cannot load its library"
    exit 77
fi
for tool in cmake cc c++ pkg-config readelf nm; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "not ok - setup: '$tool' is not on PATH"
        echo "0 passed, 1 failed"
        exit 1
    fi
done

T=$(mktemp -d "${TMPDIR:-/tmp}/phc_install.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
P="$T/prefix"

PASSED=0
FAILED=0
WHY=""
why() { WHY="${WHY:+$WHY; }$1"; }
now() { date +%s.%N; }
STEP_START=$(now)
# Ends a step: "ok - <step> (seconds)" or "not ok - <step>: <why>".
finish() {
    local took
    took=$(awk -v a="$STEP_START" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')
    if [ -z "$WHY" ]; then
        PASSED=$((PASSED + 1))
        echo "ok - $1 ($took s)"
    else
        FAILED=$((FAILED + 1))
        echo "not ok - $1: $WHY ($took s)"
    fi
    WHY=""
    STEP_START=$(now)
}
# The last lines of a log file, on one line, for a message.
tail_of() { tail -n "${2:-6}" "$1" 2>/dev/null | tr '\n' '|' | cut -c1-900; }

# Checks embed's output (file $1): converged, and the line
# "delta = V UNIT, 95% interval [LO, HI], truth X: inside" holds X in [LO, HI].
check_embed() {
    local out=$1 line
    line=$(grep '^delta = ' "$out")
    if [ -z "$line" ]; then
        why "no 'delta = ...' line in its output [$(tail_of "$out")]"
        return
    fi
    if ! awk -v l="$line" 'BEGIN {
            if (match(l, /interval \[[^,]+, [^]]+\], truth [^:]+/) == 0) exit 1;
            s = substr(l, RSTART + 10, RLENGTH - 10); gsub(/[],[]/, " ", s);
            split(s, f, " ");   # f[1] lo, f[2] hi, f[3] "truth", f[4] x
            exit !(f[1] + 0 <= f[4] + 0 && f[4] + 0 <= f[2] + 0 && f[1] + 0 < f[2] + 0) }'; then
        why "the truth is not inside the fitted 95% interval: $line"
    fi
    grep -q 'converged after' "$out" || why "the fit did not converge [$(tail_of "$out")]"
}

# 1. install
if cmake --install "$BUILD" --prefix "$P" >"$T/install.log" 2>&1; then
    :
else
    why "cmake --install $BUILD failed (is it built?) [$(tail_of "$T/install.log")]"
fi
finish "cmake --install into a temporary prefix"

# 2. what was installed; LIBDIR as GNUInstallDirs chose it
SO=$(find "$P" -name 'libphytocal.so.0' 2>/dev/null | head -n 1)
LIBDIR=$(dirname "${SO:-$P/lib/none}")
[ -n "$SO" ] || why "no libphytocal.so.0 under $P"
[ -L "$LIBDIR/libphytocal.so" ] || why "no libphytocal.so symlink (for -lphytocal) in $LIBDIR"
[ -L "$SO" ] || why "libphytocal.so.0 is not a symlink to the versioned file"
ls "$LIBDIR"/libphytocal.so.0.* >/dev/null 2>&1 || why "no versioned libphytocal.so.0.x.y in $LIBDIR"
for h in phytocal.h fit/version.h fit/engine/problem.h fit/engine/dataset.h fit/engine/fit.h fit/config.h \
         fit/report.h fit/result_json.h model/water.h model/plant_graph.h model/status.h measurements/plant_io.h; do
    [ -f "$P/include/phytocal/$h" ] || why "missing header include/phytocal/$h"
done
[ ! -e "$P/include/phytocal/fit/cli" ] || why "fit/cli was installed"
[ -z "$(find "$P/include" -name '*_internal.h')" ] || why "an *_internal.h header was installed"
PC="$LIBDIR/pkgconfig/phytocal.pc"
[ -f "$PC" ] || why "no $PC"
[ -f "$LIBDIR/cmake/phytocal/phytocalConfig.cmake" ] || why "no $LIBDIR/cmake/phytocal/phytocalConfig.cmake"
[ -f "$LIBDIR/cmake/phytocal/phytocalConfigVersion.cmake" ] || why "no phytocalConfigVersion.cmake"
finish "installed files: library and symlinks, headers in their folders, phytocal.pc, CMake package"

# 3. the shared library itself
if [ -n "$SO" ]; then
    soname=$(readelf -d "$SO" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
    [ "$soname" = "libphytocal.so.0" ] || why "SONAME is '$soname', expected libphytocal.so.0"
    others=$(nm -D --defined-only "$SO" | awk '$3 !~ /^phc_/ {print $3}' | head -n 5 | tr '\n' ' ')
    [ -z "$others" ] || why "exports symbols other than phc_*: $others..."
    nm -D --defined-only "$SO" | grep -q ' phc_version$' || why "phc_version is not exported"
fi
finish "readelf: SONAME libphytocal.so.0, only phc_* exported"

# 4. installed headers include only C standard headers (and each other)
STD='assert|complex|ctype|errno|float|inttypes|limits|locale|math|setjmp|signal|stdarg|stdbool|stddef|stdint|stdio|stdlib|string|time|wchar'
# Known exceptions: header -> what it includes, and why that is acceptable.
#   fit/engine/provenance.h <jansson.h>: a run's provenance as a jansson
#   object; it is not in phytocal.h (only run_dir.h and simulate.h include
#   it), and a program that includes it needs libjansson-dev.
KNOWN='fit/engine/provenance.h:jansson.h'
bad=$(find "$P/include/phytocal" -name '*.h' -exec awk -v std="$STD" -v known=" $KNOWN " \
        -v root="$P/include/phytocal/" '
    /^[ \t]*#[ \t]*include[ \t]*</ {
        inc = $0; sub(/^[^<]*</, "", inc); sub(/>.*/, "", inc)
        file = substr(FILENAME, length(root) + 1)
        if (inc ~ ("^(" std ")\\.h$") || index(known, " " file ":" inc " ")) next
        printf " %s:<%s>", file, inc
    }' {} +)
[ -z "$bad" ] || why "headers include non-standard headers consumers may lack:$bad"
# each one compiles alone as strict C11, with only the prefix's include
# folders (one translation unit per header, one compiler run for all)
mkdir -p "$T/headers"
n_headers=0
while IFS= read -r h; do
    n_headers=$((n_headers + 1))
    printf '#include <%s>\n' "${h#"$P/include/"}" >"$T/headers/h$n_headers.c"
done < <(find "$P/include/phytocal" -name '*.h' | sort)
if [ "$n_headers" -eq 0 ]; then
    why "no headers installed"
elif ! cc -std=c11 -pedantic -Wall -Wextra -Werror -fsyntax-only -I"$P/include" -I"$P/include/phytocal" \
        "$T/headers"/h*.c >"$T/headers.log" 2>&1; then
    why "headers do not compile alone with -std=c11 -pedantic: $(grep -m 3 -E 'error|warning' "$T/headers.log" |
        sed "s|$P/include/||g" | tr '\n' '|')"
fi
finish "installed headers ($n_headers) compile alone as C11 and include no C++ or third-party headers (except $KNOWN)"

# 5. examples/embed through find_package(phytocal)
E="$T/embed-cmake"
if ! cmake -S "$SRC/examples/embed" -B "$E" -DCMAKE_PREFIX_PATH="$P" -DCMAKE_BUILD_TYPE=Release \
        >"$T/embed-configure.log" 2>&1; then
    why "configuring examples/embed failed [$(tail_of "$T/embed-configure.log")]"
elif ! grep -q "^phytocal_DIR:PATH=$LIBDIR/cmake/phytocal$" "$E/CMakeCache.txt"; then
    why "find_package(phytocal) found $(grep '^phytocal_DIR' "$E/CMakeCache.txt"), not the temporary prefix"
elif ! cmake --build "$E" -j1 >"$E/build.log" 2>&1; then
    why "building examples/embed failed [$(tail_of "$E/build.log")]"
elif ! "$E/embed" >"$T/embed-cmake.out" 2>&1; then
    why "embed exited $? [$(tail_of "$T/embed-cmake.out")]"
else
    check_embed "$T/embed-cmake.out"
fi
finish "examples/embed built with find_package(phytocal) fits delta (truth inside its 95% interval)"

# 6. embed.c through pkg-config
export PKG_CONFIG_PATH="$LIBDIR/pkgconfig"
flags=$(pkg-config --cflags --libs phytocal 2>"$T/pc.err")
if [ -z "$flags" ]; then
    why "pkg-config --cflags --libs phytocal failed [$(tail_of "$T/pc.err")]"
else
    case "$flags" in *"-I$P/include "*"-I$P/include/phytocal"*) ;;
        *) why "pkg-config --cflags lacks -I$P/include and -I$P/include/phytocal: $flags" ;; esac
    # shellcheck disable=SC2086
    if ! cc -std=c11 -Wall -Wextra -Werror -pedantic "$SRC/examples/embed/embed.c" $flags -lm \
            -o "$T/embed-pc" >"$T/pc-build.log" 2>&1; then
        why "cc embed.c \$(pkg-config ...) failed [$(tail_of "$T/pc-build.log")]"
    elif ! LD_LIBRARY_PATH="$LIBDIR" "$T/embed-pc" >"$T/embed-pc.out" 2>&1; then
        why "embed (pkg-config build) exited non-zero [$(tail_of "$T/embed-pc.out")]"
    else
        check_embed "$T/embed-pc.out"
        v=$(pkg-config --modversion phytocal)
        grep -q "^phytocal $v: " "$T/embed-pc.out" ||
            why "phc_version() does not print pkg-config's version $v: $(head -n 1 "$T/embed-pc.out")"
    fi
fi
finish "embed.c built with pkg-config (-std=c11 -Werror -pedantic) fits delta; phc_version() = pkg-config version"

# 7. C++ consumers: the umbrella header wraps the modules in extern "C"
cat >"$T/consumer.cc" <<'EOF'
#include <phytocal/phytocal.h>
#include <cstdio>
#include <cstring>
int main()
{
    phc_plant_graph *g = phc_plant_graph_new(1); /* one segment, 1 mm x 1 cm */
    phc_error err;
    phc_error_clear(&err);
    if (g)
        g->radius[0] = 1e-3, g->length[0] = 1e-2;
    int rc = g ? phc_plant_graph_finish(g, "cxx", &err) : 1;
    phc_plant_graph_free(g);
    std::printf("%s %s\n", phc_version(), phc_strerror(rc));
    return std::strcmp(phc_version(), PHC_VERSION_STRING) != 0 || rc != PHC_OK;
}
EOF
# shellcheck disable=SC2086
if ! c++ -std=c++17 -Wall -Wextra "$T/consumer.cc" $flags -o "$T/consumer" >"$T/cxx.log" 2>&1; then
    why "a C++ program including phytocal.h does not build [$(tail_of "$T/cxx.log")]"
elif ! LD_LIBRARY_PATH="$LIBDIR" "$T/consumer" >"$T/cxx.out" 2>&1; then
    why "the C++ program failed: $(tail_of "$T/cxx.out")"
fi
finish "a C++ program includes phytocal.h and links"

# 8. the installed command, without LD_LIBRARY_PATH
if [ ! -x "$P/bin/phytocal" ]; then
    why "no $P/bin/phytocal"
elif ! env -u LD_LIBRARY_PATH "$P/bin/phytocal" --version >"$T/version.out" 2>&1; then
    why "installed phytocal --version failed [$(tail_of "$T/version.out")]"
elif [ "$(head -n 1 "$T/version.out")" != "$("$PHC" --version | head -n 1)" ]; then
    why "installed '$(head -n 1 "$T/version.out")' differs from the build's"
else
    loaded=$(env -u LD_LIBRARY_PATH ldd "$P/bin/phytocal" | sed -n 's/.*libphytocal\.so\.0 => \([^ ]*\).*/\1/p')
    [ -n "$loaded" ] && [ "$(readlink -f "$loaded")" = "$(readlink -f "$SO")" ] ||
        why "the installed command loads '$loaded', not $SO"
fi
finish "installed phytocal --version runs with the installed library"

# 9. the MPI module beside the installed library, found from there under mpirun
if [ ! -f "$LIBDIR/phytocal_mpi.so" ]; then
    why "no $LIBDIR/phytocal_mpi.so"
elif command -v mpirun >/dev/null 2>&1 && [ -x "$P/bin/phytocal" ]; then
    # (the loader's report of each process into a file of its own,
    # LD_DEBUG_OUTPUT.PID: through mpirun's merged stderr the two ranks'
    # lines could interleave, and a split line was not counted)
    mkdir -p "$T/ld"
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 mpirun -np 2 \
        env -u LD_LIBRARY_PATH LD_DEBUG=libs LD_DEBUG_OUTPUT="$T/ld/rank" "$P/bin/phytocal" sensitivity \
        "$T/missing.yaml" >"$T/mpi.out" 2>&1
    # the path as the loader wrote it (PREFIX/bin/../lib/...), resolved
    n=0
    for f in $(cat "$T"/ld/rank.* 2>/dev/null | sed -n 's/.*calling init: \(.*phytocal_mpi\.so\)$/\1/p'); do
        [ "$(readlink -f "$f")" = "$(readlink -f "$LIBDIR/phytocal_mpi.so")" ] && n=$((n + 1))
    done
    [ "$n" = 2 ] || why "mpirun -np 2 of the installed command loaded $LIBDIR/phytocal_mpi.so $n times, expected 2"
fi
finish "phytocal_mpi.so installed beside the library; the installed command loads it under mpirun"

# 10. the modules: beside the library, loaded only when a call needs them
for m in ceres photo mesh netcdf; do
    [ -f "$LIBDIR/phytocal_$m.so" ] || why "no $LIBDIR/phytocal_$m.so"
done
if [ -x "$P/bin/phytocal" ]; then
    env -u LD_LIBRARY_PATH LD_DEBUG=files "$P/bin/phytocal" version >/dev/null 2>"$T/version.ld"
    heavy=$(grep -o 'file=[^ ]*\(phytocal_[a-z]*\|libopencv_[a-z]*\|libnetcdf\|libassimp\|libceres\|libhdf5\|libplplot\|liblapacke\|libopenblas\|libxml2\)[^ ]*' \
            "$T/version.ld" | sort -u | tr '\n' ' ')
    [ -z "$heavy" ] || why "phytocal version loaded $heavy"
    grep -q 'file=.*libphytocal' "$T/version.ld" ||
        why "LD_DEBUG=files shows no library load (is the loader's debug output available?)"
    if ! (cd "$T" && env -u LD_LIBRARY_PATH LD_DEBUG=files "$P/bin/phytocal" fit \
            "$SRC/measurements/examples/enzyme_kinetics/enzyme.yaml" -o "$T/enzyme" >"$T/fit.out" 2>"$T/fit.ld"); then
        why "installed phytocal fit of the enzyme example failed [$(grep -v '^ *[0-9]*:' "$T/fit.ld" | tail -n 3 | tr '\n' '|')]"
    else
        # the command finds the library as bin/../lib (RUNPATH $ORIGIN/../lib)
        ceres=$(sed -n 's/.*file=\([^ ]*phytocal_ceres\.so\) .*/\1/p' "$T/fit.ld" | head -n 1)
        [ -n "$ceres" ] && [ "$(readlink -f "$ceres")" = "$(readlink -f "$LIBDIR/phytocal_ceres.so")" ] ||
            why "the installed fit did not load $LIBDIR/phytocal_ceres.so (loaded: '${ceres}')"
        # PLplot (the plots): opened by the library when the fit draws
        # (measurements/lazy_library.c); the analysis needs no LAPACKE
        # (model/jacobi_svd.h), so a curve fit does not load it (OpenBLAS
        # comes with the Ceres module's SuiteSparse)
        grep -q "file=[^ ]*libplplot\.so" "$T/fit.ld" || why "the installed fit did not load libplplot"
        ! grep -q "file=[^ ]*liblapacke" "$T/fit.ld" || why "the installed curve fit loaded liblapacke"
    fi
fi
cat >"$T/modules.c" <<'EOF'
#include <phytocal/measurements/photo.h>
#include <phytocal/measurements/support_mesh.h>
#include <phytocal/phytocal.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
/* photo and mesh calls through the modules; argv[1] the PNG to write, argv[2]
 * "missing" when PHYTOCAL_MODULE_DIR names an empty folder */
int main(int argc, char **argv)
{
    phc_error err;
    phc_error_clear(&err);
    int missing = argc > 2 && strcmp(argv[2], "missing") == 0;
    phc_image img, rd;
    memset(&rd, 0, sizeof rd);
    if (phc_image_alloc(&img, 4, 3, &err))
        return printf("alloc: %s\n", err.message), 1;
    for (size_t i = 0; i < 3 * 4 * 3; ++i)
        img.data[i] = (double)(i % 11) / 10.0;
    int rc = phc_photo_write_png(argv[1], &img, &err);
    if (missing) {
        printf("photo: %s: %s\n", phc_strerror(rc), err.message);
        phc_support_mesh *m = phc_support_mesh_from_arrays((double[]){0, 0, 0, 1, 0, 0, 0, 1, 0}, 3,
                                                           (size_t[]){0, 1, 2}, 1, "tri", &err);
        printf("mesh: %s: %s\n", m ? "loaded" : phc_strerror(err.status), err.message);
        return rc != PHC_ERR_IO || m != NULL;
    }
    if (rc || (rc = phc_photo_read(argv[1], &rd, &err)))
        return printf("photo: %s\n", err.message), 1;
    double worst = 0;
    for (size_t i = 0; i < 3 * 4 * 3; ++i)
        worst = fmax(worst, fabs(rd.data[i] - img.data[i]));
    phc_support_mesh *m = phc_support_mesh_from_arrays((double[]){0, 0, 0, 1, 0, 0, 0, 1, 0}, 3,
                                                       (size_t[]){0, 1, 2}, 1, "tri", &err);
    double c[3] = {0}, n[3] = {0};
    int q = m ? phc_support_mesh_closest(m, (double[]){0.25, 0.25, 2}, c, n) : -1;
    printf("png round trip: %zux%zu, worst %.4f; closest (%.3f, %.3f, %.3f)\n", rd.width, rd.height,
           worst, c[0], c[1], c[2]);
    FILE *maps = fopen("/proc/self/maps", "r");
    char line[4096];
    while (maps && fgets(line, sizeof line, maps))
        if (strstr(line, "phytocal_photo.so") || strstr(line, "phytocal_mesh.so"))
            printf("mapped:%s", strrchr(line, ' ') + 1);
    if (maps)
        fclose(maps);
    const int ok = q == 0 && worst <= 0.5 / 255 + 1e-12 && rd.width == 4 && rd.height == 3 &&
                   fabs(c[0] - 0.25) + fabs(c[1] - 0.25) + fabs(c[2]) < 1e-12;
    phc_support_mesh_free(m);
    phc_image_free(&img);
    phc_image_free(&rd);
    return !ok;
}
EOF
# shellcheck disable=SC2086
if ! cc -std=c11 -Wall -Wextra "$T/modules.c" $flags -lm -o "$T/modules" >"$T/modules-build.log" 2>&1; then
    why "cc modules.c \$(pkg-config ...) failed [$(tail_of "$T/modules-build.log")]"
elif ! LD_LIBRARY_PATH="$LIBDIR" "$T/modules" "$T/small.png" >"$T/modules.out" 2>&1; then
    why "photo/mesh through the installed modules failed [$(tail_of "$T/modules.out")]"
else
    for m in photo mesh; do
        grep -q "^mapped:$(readlink -f "$LIBDIR/phytocal_$m.so")\$" "$T/modules.out" ||
            why "the program did not map $LIBDIR/phytocal_$m.so [$(tail_of "$T/modules.out")]"
    done
    mkdir -p "$T/empty"
    if ! PHYTOCAL_MODULE_DIR="$T/empty" LD_LIBRARY_PATH="$LIBDIR" "$T/modules" "$T/small2.png" missing \
            >"$T/missing.out" 2>&1; then
        why "with no modules the calls did not fail with PHC_ERR_IO [$(tail_of "$T/missing.out")]"
    else
        grep -q "^photo: .*: $T/empty/phytocal_photo.so: cannot load the photos (OpenCV) module" "$T/missing.out" ||
            why "the missing photo module's message does not name it and its path: $(tail_of "$T/missing.out")"
        grep -q "^mesh: .*: $T/empty/phytocal_mesh.so: cannot load the support meshes" "$T/missing.out" ||
            why "the missing mesh module's message does not name it and its path: $(tail_of "$T/missing.out")"
    fi
fi
finish "modules beside the library: version loads none (nor PLplot, LAPACKE, OpenBLAS, libxml2), fit loads Ceres and PLplot (not LAPACKE), photo and mesh calls theirs, a missing one is PHC_ERR_IO naming it"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
