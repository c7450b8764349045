"""The nodes' declared parameters: the schema type, one schema per node and the reference."""
