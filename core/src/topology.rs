//! Adjacency derived from the face list: edges, vertex rings, boundary loops, components, manifold checks.
