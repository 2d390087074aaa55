# Tiny data for the seq CLI tests (sourced by seq_train.sh and
# seq_complete.sh; not a test itself).

# Network options small enough to train in a second.
small=(--window 8 --batch 2 --hidden 16 --latent 8 --lstm-layers 2 --threads 1)

# write_walk_csv FILE: two joints swinging for 60 frames at 25 fps, and a
# torso column that is not a joint.
write_walk_csv() {
  awk 'BEGIN { print "time_s,hip,knee,torso_x";
    for (f = 0; f < 60; f++) { t = f / 25; printf "%g,%g,%g,%g\n", t, 0.5 * sin(7.85 * t), 0.3 * cos(7.85 * t), t } }' \
    > "$1"
}

# write_plate DIR: a 6 x 6 plate bending to and fro, 30 OBJ frames
# DIR/frame_0000.obj ... frame_0029.obj.
write_plate() {
  mkdir -p "$1"
  awk -v dir="$1" 'BEGIN { n = 6;
    for (f = 0; f < 30; f++) {
      file = sprintf("%s/frame_%04d.obj", dir, f); a = 0.5 * sin(6.2832 * f / 12);
      for (i = 0; i < n; i++) for (j = 0; j < n; j++) { x = i / (n - 1); y = j / (n - 1);
        printf "v %g %g %g\n", x * cos(a * x), y, x * sin(a * x) > file }
      for (i = 0; i < n - 1; i++) for (j = 0; j < n - 1; j++) { v = i * n + j + 1;
        printf "f %d %d %d\nf %d %d %d\n", v, v + n, v + 1, v + 1, v + n, v + n + 1 > file }
      close(file) } }'
}
