#include "bvc3d/agent/learning_walk.hpp"

#include <sstream>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

class LearningWalk : public Agent {
public:
    LearningWalk(const World& world, const NavigationSpaceSpec& spec, std::unique_ptr<Agent> walk)
        : spec_(spec), space_(make_navigation_space(world.description(), spec)), walk_(std::move(walk)) {
        visited_.assign(space_->coverage_size(), 0);
        visits_.assign(spec_.goals.size(), 0);
        inside_.assign(spec_.goals.size(), 0);
    }
    std::optional<ModelStep> next(double t_end) override {
        if (done_) return std::nullopt;
        auto step = walk_->next(t_end);
        if (!step) return step;
        last_t_ = step->t;
        const Vec3 p = step->pose.position();
        if (const auto c = space_->coverage_cell(p); c && !visited_[*c]) {
            visited_[*c] = 1;
            ++covered_;
        }
        bool goals_done = true;
        for (std::size_t g = 0; g < spec_.goals.size(); ++g) {
            const bool in = space_->distance(p, spec_.goals[g].p) <= spec_.nav.goal_radius;
            if (in && !inside_[g]) ++visits_[g];
            inside_[g] = in;
            goals_done = goals_done && visits_[g] >= spec_.nav.goal_visits;
        }
        done_ = goals_done && coverage() >= spec_.nav.coverage;
        return step;
    }
    double time() const override { return walk_->time(); }
    bool finished() const override { return done_ || walk_->finished(); }
    std::vector<std::pair<std::string, double>> report() const override {
        std::vector<std::pair<std::string, double>> out{{"learn_s", last_t_}, {"coverage", coverage()}};
        for (std::size_t g = 0; g < visits_.size(); ++g) out.emplace_back("visits", double(visits_[g]));
        return out;
    }
    std::string save_state() const override {
        std::ostringstream os;
        os << "learning_walk " << (done_ ? 1 : 0) << ' ' << format_number(last_t_) << ' ' << covered_ << ' '
           << visits_.size();
        for (std::size_t g = 0; g < visits_.size(); ++g) os << ' ' << visits_[g] << ' ' << int(inside_[g]);
        os << ' ' << visited_.size() << ' ';
        for (char v : visited_) os << (v ? '1' : '0');
        os << '\n' << walk_->save_state();
        return os.str();
    }
    void restore_state(const std::string& text) override {
        std::istringstream is(text);
        std::string kind, cells, last;
        int done = 0;
        std::size_t covered = 0, goals = 0, size = 0;
        is >> kind >> done >> last >> covered >> goals;
        if (!is || kind != "learning_walk" || goals != visits_.size())
            throw InputError("saved state is not this learning walk's");
        for (std::size_t g = 0; g < goals; ++g) {
            int inside = 0;
            is >> visits_[g] >> inside;
            inside_[g] = static_cast<char>(inside != 0);
        }
        is >> size >> cells;
        if (!is || size != visited_.size() || cells.size() != size)
            throw InputError("saved learning-walk state is corrupt");
        for (std::size_t i = 0; i < size; ++i) visited_[i] = static_cast<char>(cells[i] == '1');
        try {
            last_t_ = std::stod(last);
        } catch (const std::exception&) {
            throw InputError("saved learning-walk state is corrupt");
        }
        covered_ = covered;
        done_ = done != 0;
        is.ignore(1);
        walk_->restore_state(std::string(std::istreambuf_iterator<char>(is), {}));
    }

private:
    double coverage() const {
        const std::size_t free = space_->coverage_cells();
        return free ? double(covered_) / double(free) : 1.0;
    }
    NavigationSpaceSpec spec_;
    std::unique_ptr<NavigationSpace> space_;
    std::unique_ptr<Agent> walk_;
    std::vector<char> visited_, inside_;
    std::vector<int> visits_;
    std::size_t covered_ = 0;
    bool done_ = false;
    double last_t_ = 0.0;  // the last step's time: how long learning took
};

}  // namespace

LearningWalkSpec::LearningWalkSpec(NavigationSpaceSpec spec) : spec_(std::move(spec)), walk_(navigation_walk(spec_)) {}

void LearningWalkSpec::validate() const {
    spec_.nav.validate();
    spec_.check_goals_shape();
    walk_->validate();
}

void LearningWalkSpec::check_world(const WorldDescription& world) const {
    walk_->check_world(world);
    const auto space = make_navigation_space(world, spec_);
    for (std::size_t i = 0; i < spec_.goals.size(); ++i) space->check_goal(i, spec_.goals[i]);
}

std::unique_ptr<Agent> LearningWalkSpec::make(const World* world, std::uint64_t seed) const {
    if (!world) throw InputError("navigation's learning walk needs a world");
    return std::make_unique<LearningWalk>(*world, spec_, walk_->make(world, seed));
}

std::string LearningWalkSpec::key() const {
    std::string k = walk_->key();
    k += "learning until: coverage " + format_number(spec_.nav.coverage) + " of " +
         format_number(spec_.nav.coverage_cell) + " m cells, " + std::to_string(spec_.nav.goal_visits) +
         " visits within " + format_number(spec_.nav.goal_radius) + " m of goals";
    for (const NavigationGoal& g : spec_.goals)
        for (int d = 0; d < g.dims; ++d) {
            k += d == 0 ? ' ' : ',';
            k += format_number(g.p[d]);
        }
    return k + "\n";
}

}  // namespace bvc3d
