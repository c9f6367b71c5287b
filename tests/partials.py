"""Central differences of a parametrisation p(u, v): the test suite's one reference for derivatives of a surface."""


def central_partials(p, u, v, h=1e-4):
    """p_u, p_v, p_uu, p_uv, p_vv of ``p(u, v)`` by central differences (errors O(h^2))."""
    pu = (p(u + h, v) - p(u - h, v)) / (2 * h)
    pv = (p(u, v + h) - p(u, v - h)) / (2 * h)
    puu = (p(u + h, v) - 2 * p(u, v) + p(u - h, v)) / h**2
    puv = (p(u + h, v + h) - p(u + h, v - h) - p(u - h, v + h) + p(u - h, v - h)) / (4 * h * h)
    pvv = (p(u, v + h) - 2 * p(u, v) + p(u, v - h)) / h**2
    return pu, pv, puu, puv, pvv
