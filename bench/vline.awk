# vline.awk: the figures of render's per-view lines (with -v), read by name,
# not by position, so that fields added later do not shift the others.
#   render: OUT: WxH, 39.2 ms, 26.75 Mrays/s, 40.1% hit, 1.20% edge pixels,
#   0.17% supersampled; primary 1.05 Mrays 26.96 Mrays/s, shadow 0.42 Mrays,
#   ao 0.00 Mrays, 4.67 Mrays/s
# After the ';' a field "KIND N Mrays" counts the rays of a kind and may carry
# its own rate ("KIND N Mrays R Mrays/s" or "KIND R Mrays/s"); a bare
# "R Mrays/s" is the rate of the kinds named since the last rate: the kind's
# own when only one of them traced rays, else their combined ("secondary").
# Prints per view: ms supersampled_pct primary shadow ao secondary (Mrays/s;
# "-" when not printed; supersampled 0 without --aa).
# Usage: awk -f bench/vline.awk render.log
function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); return s }
function out(k) { return (k in rate) ? rate[k] : "-" }
/^render: .*: [0-9]+x[0-9]+, / {
    line = $0
    sub(/^render: .*: [0-9]+x[0-9]+, /, "", line)
    split("", rate); split("", count); ng = 0; ms = "-"; ss = 0
    nsec = split(line, part, ";")
    for (p = 1; p <= nsec; p++) {
        nf = split(part[p], f, ",")
        for (i = 1; i <= nf; i++) {
            n = split(trim(f[i]), w, " ")
            if (p == 1) { # the view's own figures
                if (n == 2 && w[2] == "ms") ms = w[1]
                if (n == 2 && w[2] == "supersampled") { ss = w[1]; sub(/%$/, "", ss) }
                continue
            }
            if (n >= 3 && w[3] == "Mrays") {
                count[w[1]] = w[2]; group[++ng] = w[1]
                if (n >= 5 && w[5] == "Mrays/s") { rate[w[1]] = w[4]; ng = 0 }
            } else if (n == 3 && w[3] == "Mrays/s") {
                rate[w[1]] = w[2]
            } else if (n == 2 && w[2] == "Mrays/s") {
                busy = 0
                for (g = 1; g <= ng; g++) if (count[group[g]] + 0 > 0) { busy++; only = group[g] }
                if (busy == 1) rate[only] = w[1]
                if (ng > 1) rate["secondary"] = w[1]
                ng = 0
            }
        }
    }
    print ms, ss, out("primary"), out("shadow"), out("ao"), out("secondary")
}
