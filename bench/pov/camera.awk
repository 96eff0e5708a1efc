# camera.awk: our camera (docs/INTERFACE.md) as POV-Ray explicit camera vectors.
# POV-Ray shoots the ray of pixel (i, j) along direction + (x - 1/2) right
# + (1/2 - y) up with x = (i + 1/2)/W, y = (j + 1/2)/H; given our forward,
# 2h(W/H) right and 2h up' as those vectors it is exactly our ray, and no
# handedness flip is needed (pov.sh check verifies it on an off-centre sphere).
# Usage: awk -v eye=X,Y,Z -v target=X,Y,Z -v up=X,Y,Z -v fov=DEG -v w=W -v hgt=H -f camera.awk
function norm(v,  n) { n = sqrt(v[1]^2 + v[2]^2 + v[3]^2); v[1] /= n; v[2] /= n; v[3] /= n }
BEGIN {
    split(eye, E, ","); split(target, T, ","); split(up, U, ",")
    for (a = 1; a <= 3; a++) F[a] = T[a] - E[a]
    norm(F)
    R[1] = F[2] * U[3] - F[3] * U[2]; R[2] = F[3] * U[1] - F[1] * U[3]; R[3] = F[1] * U[2] - F[2] * U[1]
    norm(R)
    V[1] = R[2] * F[3] - R[3] * F[2]; V[2] = R[3] * F[1] - R[1] * F[3]; V[3] = R[1] * F[2] - R[2] * F[1]
    h = sin(fov * 3.141592653589793 / 360) / cos(fov * 3.141592653589793 / 360)
    sr = 2 * h * w / hgt; su = 2 * h
    printf "camera { perspective\n  location <%.17g, %.17g, %.17g>\n", E[1], E[2], E[3]
    printf "  direction <%.17g, %.17g, %.17g>\n", F[1], F[2], F[3]
    printf "  right <%.17g, %.17g, %.17g>\n", sr * R[1], sr * R[2], sr * R[3]
    printf "  up <%.17g, %.17g, %.17g>\n}\n", su * V[1], su * V[2], su * V[3]
}
