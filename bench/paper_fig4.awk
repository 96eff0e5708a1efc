# paper_fig4.awk: the paper's Figure 4 times in seconds (Stolte & Caubet,
# 100 MHz workstation), for scene s (blobs_a = image 1, blobs_b = image 2),
# size n and split k (k upper levels + 10-k lower). Prints nan when absent.
# Usage: awk -v s=blobs_a -v n=1024 -v k=4 -f paper_fig4.awk
BEGIN {
    t["blobs_a", 1024] = "190 141 123 121"; t["blobs_a", 512] = "47 35 31 30"
    t["blobs_a", 256] = "12 9 7 7"
    t["blobs_b", 1024] = "231 169 145 147"; t["blobs_b", 512] = "58 42 36 37"
    t["blobs_b", 256] = "14 10 9 9"
    if (!((s, n) in t) || k < 4 || k > 7) { print "nan"; exit }
    split(t[s, n], v, " ")
    print v[k - 3]
}
