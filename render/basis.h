/* basis: an orthonormal pair across a unit vector (Duff et al. 2017,
 * "Building an Orthonormal Basis, Revisited": branchless, no normalisation). */
#ifndef BASIS_H
#define BASIS_H

/* t and b such that t, b, n is an orthonormal basis, for unit n. */
static inline void basis_across(const double n[3], double t[3], double b[3])
{
    const double sg = n[2] >= 0.0 ? 1.0 : -1.0;
    const double ka = -1.0 / (sg + n[2]), kb = n[0] * n[1] * ka;
    t[0] = 1.0 + sg * n[0] * n[0] * ka;
    t[1] = sg * kb;
    t[2] = -sg * n[0];
    b[0] = kb;
    b[1] = sg + n[1] * n[1] * ka;
    b[2] = -n[1];
}

#endif
