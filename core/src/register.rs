//! Rigid/similarity registration of two meshes or point sets (PCA, ICP, Procrustes).
