//! The kernels: the Verlet list and the cell lists that fill it, the contact sweep and
//! the kernel driver (four contacts at a time, eight on AVX-512), and the thread pool
//! that runs them on parts of the list. They take slices and views of the grains.
//! May use: `physics`, `error`. They know nothing of the scene, the World or the Engine.

#[cfg(all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))]
pub mod avx2;
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
pub mod avx512;
pub mod cells;
pub mod driver;
pub mod pairs;
pub mod sweep;
pub mod threads;
pub mod wide;
