#include "bvc3d/agent/free_space_grid.hpp"

#include <cmath>

namespace bvc3d {

FreeSpaceGrid::FreeSpaceGrid(const BodyCollider& body, double cell, double max_cells) : cell_(cell) {
    const auto box = body.walkable().bounds();
    while ((box.sizes().x() / cell_ + 1) * (box.sizes().y() / cell_ + 1) > max_cells) cell_ *= 2;
    origin_ = box.min();
    nx_ = std::max(1, static_cast<int>(std::ceil(box.sizes().x() / cell_)));
    ny_ = std::max(1, static_cast<int>(std::ceil(box.sizes().y() / cell_)));
    room_.assign(static_cast<std::size_t>(nx_) * ny_, 0.0f);
    for (std::size_t i = 0; i < room_.size(); ++i) {
        const Vec2 p = center(cell_at(i));
        if (body.walkable().contains(p)) room_[i] = static_cast<float>(std::max(0.0, body.room(p)));
    }
}

std::optional<GridCell> FreeSpaceGrid::cell_of(const Vec2& p) const {
    const GridCell c{static_cast<int>(std::floor((p.x() - origin_.x()) / cell_)),
                     static_cast<int>(std::floor((p.y() - origin_.y()) / cell_))};
    if (!contains(c)) return std::nullopt;
    return c;
}

std::vector<int> FreeSpaceGrid::parts(double radius, int& count) const {
    std::vector<int> label(room_.size(), -1);
    std::vector<std::size_t> stack;
    count = 0;
    for (std::size_t start = 0; start < room_.size(); ++start) {
        if (label[start] >= 0 || room_[start] < radius) continue;
        label[start] = count;
        stack.assign(1, start);
        while (!stack.empty()) {
            const GridCell c = cell_at(stack.back());
            stack.pop_back();
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const GridCell n{c.x + dx, c.y + dy};
                    if ((dx == 0 && dy == 0) || !contains(n)) continue;
                    const std::size_t k = index(n);
                    if (label[k] >= 0 || room_[k] < radius) continue;
                    label[k] = count;
                    stack.push_back(k);
                }
        }
        ++count;
    }
    return label;
}

}  // namespace bvc3d
