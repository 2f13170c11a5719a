//! Spatial queries: nearest vertex, closest point on a triangle mesh (AABB tree).
