pub(crate) mod sdfgrid;
pub(crate) mod serialized;
pub(crate) mod shapes;
