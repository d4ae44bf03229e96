#!/usr/bin/env bash
# Writes the bad inputs that are not committed (huge, sparse, repetitive or special files) into
# the directory given, for run.sh; the tables name them @tmp/NAME.
set -euo pipefail
out=$1

repeat() { # repeat TEXT COUNT: TEXT written COUNT times, no newline
    awk -v text="$1" -v count="$2" 'BEGIN { for (i = 0; i < count; i++) printf "%s", text }'
}

# Bigger than any input limit, without using the disk: sparse files.
truncate -s 3G "$out/huge.toml" "$out/huge.obj" "$out/huge.ply"

# TOML nested 100,000 levels deep, each way TOML nests: dotted keys, table headers, arrays and
# inline tables.
{ repeat 'a.' 100000; echo 'a = 1'; } >"$out/deep_dotted.toml"
{ echo -n '['; repeat 'a.' 100000; echo 'a]'; } >"$out/deep_header.toml"
{ echo -n 'a = '; repeat '[' 100000; repeat ']' 100000; echo; } >"$out/deep_array.toml"
{ echo -n 'a = '; repeat '{a=' 100000; echo -n 1; repeat '}' 100000; echo; } \
    >"$out/deep_inline.toml"
# Just past the documented limit, and a scene whose geometry is fine but whose key is too deep.
{ echo 'name = "x"'; echo -n 'x.'; repeat 'a.' 70; echo 'a = 1'; } >"$out/deep71.toml"

# Special files reached through names a loader accepts: a symbolic link to /dev/zero with a
# mesh or TOML extension, a link loop, and files that name the FIFO run.sh makes.
ln -s /dev/zero "$out/zero.obj"
ln -s /dev/zero "$out/zero.toml"
ln -s /dev/zero "$out/zero.ply"
ln -s loop_b.obj "$out/loop_a.obj"
ln -s loop_a.obj "$out/loop_b.obj"
ln -s fifo "$out/fifo.obj"
ln -s fifo "$out/fifo.toml"
printf 'mtllib fifo\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$out/mtllib_fifo.obj"
printf 'mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$out/mtllib_zero.obj"
ln -s /dev/zero "$out/zero.mtl"
truncate -s 3G "$out/huge.mtl"
printf 'mtllib huge.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$out/mtllib_huge.obj"
printf '[[meshes]]\npath = "fifo.obj"\n' >"$out/mesh_fifo.toml"
printf '[[meshes]]\npath = "zero.obj"\n' >"$out/mesh_zero.toml"
printf '[[meshes]]\npath = "huge.obj"\n' >"$out/mesh_huge.toml"
printf '[[meshes]]\npath = "mtllib_fifo.obj"\n' >"$out/mesh_mtllib_fifo.toml"

# An ASCII OBJ of 1,000,000 vertex lines with no face (a point cloud), 20 MB.
awk 'BEGIN { for (i = 0; i < 1000000; i++) print "v 0 0 0" }' >"$out/points.obj"

# A glTF whose buffer is a symbolic link to /dev/zero.
ln -s /dev/zero "$out/zero.bin"
cat >"$out/gltf_zero.gltf" <<'GLTF'
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}],
 "bufferViews": [{"buffer": 0, "byteLength": 36}],
 "buffers": [{"uri": "zero.bin", "byteLength": 36}]}
GLTF

# glTF JSON nested 100,000 levels deep.
{ echo -n '{"asset": {"version": "2.0"}, "extras": '; repeat '[' 100000; repeat ']' 100000
  echo '}'; } >"$out/deep.gltf"

# Symbolic links that lead nowhere.
ln -s no_such_file "$out/dangling.toml"
ln -s no_such_file "$out/dangling.obj"
printf '[[meshes]]\npath = "dangling.obj"\n' >"$out/mesh_dangling.toml"
printf '[[meshes]]\npath = "loop_a.obj"\n' >"$out/mesh_loop.toml"
