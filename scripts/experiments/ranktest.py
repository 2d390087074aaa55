"""The Mann-Whitney U rank test, for comparing evolve runs (table5.sh).

mann_whitney_u(a, b) ranks the pooled samples (ties share their mean rank)
and returns U for a, U for b, and the probability of a U for a this small
or smaller if both samples came from one distribution (one-sided: a tends
lower), and the two-sided probability. Without ties and with both samples
of at most 25 the probabilities are exact (the count of rank arrangements
for every U); otherwise they come from the normal approximation with the
tie correction of the variance and a continuity correction.
"""
import math


def ranks(values):
    """1-based ranks of values, ties given the mean of the ranks they span."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        mean = (i + j) / 2 + 1
        for k in range(i, j + 1):
            out[order[k]] = mean
        i = j + 1
    return out


def u_distribution(n, m):
    """counts[u] = how many of the C(n+m, n) arrangements give U = u."""
    # f[i][j][u]: arrangements of i a's and j b's with U = u (U counts the
    # (a, b) pairs with the b first).
    f = [[None] * (m + 1) for _ in range(n + 1)]
    for i in range(n + 1):
        for j in range(m + 1):
            if i == 0 or j == 0:
                f[i][j] = [1]
                continue
            # The largest value is an a (it beats all j b's) or a b.
            with_a = [0] * j + f[i - 1][j]
            with_b = f[i][j - 1]
            size = max(len(with_a), len(with_b))
            f[i][j] = [(with_a[u] if u < len(with_a) else 0) +
                       (with_b[u] if u < len(with_b) else 0) for u in range(size)]
    return f[n][m]


def normal_cdf(z):
    return 0.5 * math.erfc(-z / math.sqrt(2))


def mann_whitney_u(a, b):
    n, m = len(a), len(b)
    if n == 0 or m == 0:
        raise ValueError("both samples need at least one value")
    r = ranks(list(a) + list(b))
    u_a = sum(r[:n]) - n * (n + 1) / 2
    u_b = n * m - u_a
    pooled = sorted(list(a) + list(b))
    ties = []
    i = 0
    while i < len(pooled):
        j = i
        while j + 1 < len(pooled) and pooled[j + 1] == pooled[i]:
            j += 1
        if j > i:
            ties.append(j - i + 1)
        i = j + 1
    result = {"u_a": u_a, "u_b": u_b, "n_a": n, "n_b": m}
    if not ties and n <= 25 and m <= 25:
        counts = u_distribution(n, m)
        total = sum(counts)
        k = int(round(u_a))
        result["p_less"] = sum(counts[: k + 1]) / total
        small = int(round(min(u_a, u_b)))
        result["p_two_sided"] = min(1.0, 2 * sum(counts[: small + 1]) / total)
        result["method"] = "exact"
        return result
    big_n = n + m
    mean = n * m / 2
    tie_term = sum(t ** 3 - t for t in ties) / (big_n * (big_n - 1))
    var = n * m / 12 * ((big_n + 1) - tie_term)
    result["variance"] = var
    if var <= 0:  # every value equal
        result.update(p_less=1.0, p_two_sided=1.0, z=0.0, method="normal")
        return result
    sd = math.sqrt(var)
    z_less = (u_a - mean + 0.5) / sd
    small = min(u_a, u_b)
    z_two = (small - mean + 0.5) / sd
    result["z"] = (u_a - mean) / sd
    result["p_less"] = normal_cdf(z_less)
    result["p_two_sided"] = min(1.0, 2 * normal_cdf(z_two))
    result["method"] = "normal"
    return result


def median(xs):
    s = sorted(xs)
    k = len(s) // 2
    return s[k] if len(s) % 2 else (s[k - 1] + s[k]) / 2


def spread_test(a, b):
    """Whether a varies more than b: the U test on each value's distance from
    its own sample's median (larger distances in a: small p_less for b)."""
    da = [abs(x - median(a)) for x in a]
    db = [abs(x - median(b)) for x in b]
    return mann_whitney_u(db, da)
