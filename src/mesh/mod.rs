//! Where the equations live: the regular background grid, the Gauss rules of the finite
//! elements, and the size a discretisation will need.

pub mod budget;
pub mod grid;
pub mod quadrature;
