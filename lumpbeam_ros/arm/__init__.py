"""The flexible arm: links of lumped segments joined by prescribed revolute joints."""
